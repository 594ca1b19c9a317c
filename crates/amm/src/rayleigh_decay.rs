//! The Rayleigh damping of the AMM measured on a free decay (`docs/amm.md` 11.2, Eqs. D14, D19):
//! after a move the sliders rest, and each of the first two modes, filtered out of the stored
//! coordinates by the pose's own modes, decays at `alpha / 2 + beta omega_k^2 / 2`.

use flexstar_model::{AmmSettings, Damping, Experiment, ModeFamily, RestPose, Sliders};

use crate::pose_modes::PoseModel;
use crate::solver::integrate;

/// A brisk move to an off-centre pose, then 1.5 s at rest.
const MOVE: &str = "name = \"decay\"\n[time]\nt_end = 1.7\ndt_out = 0.001\n[trajectory]\nkind = \"quintic\"\n\
                    from = { Gx = 0.0, Gy = 0.0, theta = 0.0 }\nto = { Gx = 0.03, Gy = -0.02, theta = 0.15 }\n\
                    t0 = 0.0\nt1 = 0.2\n";

/// The modal coordinates `eta_k = phi_k^T M q` (mass-normalised shapes) of the first two modes
/// at the final pose, sampled at the steps after the move, with their angular frequencies.
/// `robot`: the robot as built instead of the file's (`docs/amm.md` 13).
fn modal_histories(damping: Damping, robot: Option<flexstar_model::Robot>) -> ([f64; 2], Vec<[f64; 2]>, f64) {
    let mut exp = Experiment::from_toml_str(MOVE, std::path::Path::new("decay.toml")).unwrap();
    exp.damping = damping;
    let mut problem = exp.problem().unwrap();
    if let Some(r) = robot {
        problem = problem.with_robot(r).unwrap();
    }
    let eq = crate::star::Star::new(&problem);
    let settings = AmmSettings::paper(ModeFamily::FreeFree, 20);
    let st = flexstar_kinematics::RigidState::at(problem.robot(), &exp.trajectory, exp.time.t_end).unwrap();
    let pose = RestPose {
        s: st.s.map(|s| s.v),
        g: st.g.map(|g| g.v),
        theta: st.theta.v,
        xp: st.xp.map(|x| x.v),
    };
    let modes = PoseModel::of_robot(problem.robot(), ModeFamily::FreeFree, 20)
        .unwrap()
        .modes_at(&pose, Sliders::Locked, 2)
        .unwrap();
    let (n, m) = (modes.system.n, &modes.system.m);
    let mphi: Vec<Vec<f64>> = modes.shapes[..2]
        .iter()
        .map(|p| (0..n).map(|a| (0..n).map(|b| m[a * n + b] * p[b]).sum()).collect())
        .collect();
    let mut eta = Vec::new();
    integrate(&eq, &settings, 20, true, |_, q| {
        eta.push([0, 1].map(|k| mphi[k].iter().zip(q).map(|(a, b)| a * b).sum::<f64>()));
    })
    .unwrap();
    let h = exp.time.t_end / (eta.len() - 1) as f64;
    let rest = (0.25 / h).ceil() as usize;
    let omega = [0, 1].map(|k| 2.0 * std::f64::consts::PI * modes.freq_hz[k]);
    (omega, eta.split_off(rest), h)
}

/// The decay rate [1/s] of a sampled damped oscillation: the least-squares slope of the
/// logarithm of its successive positive peaks (the peaks of `e^(-s t) cos(omega_d t)`
/// are `e^(-s t)` times a constant).
fn decay_rate(x: &[f64], h: f64) -> f64 {
    let peaks: Vec<(f64, f64)> = (1..x.len() - 1)
        .filter(|&i| x[i] > 0.0 && x[i] >= x[i - 1] && x[i] > x[i + 1])
        .map(|i| {
            // the parabola through three samples: its vertex, time and value
            let (a, b, c) = (x[i - 1], x[i], x[i + 1]);
            let d = 0.5 * (a - c) / (a - 2.0 * b + c);
            ((i as f64 + d) * h, (b - 0.25 * (a - c) * d).ln())
        })
        .collect();
    let n = peaks.len() as f64;
    let (mt, my) = peaks.iter().fold((0.0, 0.0), |(a, b), (t, y)| (a + t / n, b + y / n));
    let (sxy, sxx) = peaks.iter().fold((0.0, 0.0), |(a, b), (t, y)| {
        (a + (t - mt) * (y - my), b + (t - mt) * (t - mt))
    });
    -sxy / sxx
}

#[test]
fn the_first_two_modes_decay_at_the_rayleigh_rates() {
    decay_at_the_rayleigh_rates(None);
}

#[test]
fn the_first_two_modes_of_a_robot_as_built_decay_at_the_rayleigh_rates() {
    // the pose's modes of the robot as built (PoseModel::of_robot, docs/amm.md 13) filter the
    // time-domain run of that robot: each decays at alpha / 2 + beta omega_k^2 / 2 with the
    // eigenproblem's omega_k, so the two agree on the frequencies
    decay_at_the_rayleigh_rates(Some(crate::star::as_built_robot(1.0)));
}

fn decay_at_the_rayleigh_rates(robot: Option<flexstar_model::Robot>) {
    for damping in [Damping::rayleigh(3.0, 0.0), Damping::rayleigh(2.0, 3e-3)] {
        let (alpha, beta) = damping.coefficients();
        let (omega, eta, h) = modal_histories(damping, robot.clone());
        for k in 0..2 {
            let x: Vec<f64> = eta.iter().map(|e| e[k]).collect();
            let measured = decay_rate(&x, h);
            // Eq. D14: zeta_k omega_k = alpha / 2 + beta omega_k^2 / 2
            let law = 0.5 * alpha + 0.5 * beta * omega[k] * omega[k];
            eprintln!(
                "alpha {alpha}, beta {beta}: mode {} at {:.3} Hz decays at {measured:.4} 1/s, law {law:.4}",
                k + 1,
                omega[k] / (2.0 * std::f64::consts::PI)
            );
            // the filter is exact for the linear system at rest; what is left is the peaks' sampling
            assert!(
                (measured / law - 1.0).abs() < 5e-3,
                "mode {}: {measured} vs {law}",
                k + 1
            );
        }
    }
}
