//! Friction in the FEM (`docs/friction.md`) against references independent of the code under
//! test: the energy balance with the friction's dissipation, the closed-form stick-slip of a
//! block on a rail with Coulomb friction, the clamped cantilever of a stuck sleeve's overhang,
//! and the frictionless run bit for bit.

#![allow(clippy::needless_range_loop)]

use flexstar_drive::SolveRequest;
use flexstar_model::{catalogue, Experiment, FemSettings, Friction, Response, RobotParams};

#[path = "support/run.rs"]
mod run;
use run::{coarse, col};

fn fem(exp: &Experiment, settings: &FemSettings, request: SolveRequest) -> Response {
    flexstar_fem::solve(&exp.problem().unwrap(), settings, request)
        .map(|s| s.response)
        .unwrap()
}

/// `[friction]` from its TOML text.
fn friction(text: &str) -> Friction {
    toml::from_str(text).unwrap()
}

/// The quintic from the origin to the general target in 0.3 s, then at rest until `t_end`.
fn quintic(t_end: f64) -> Experiment {
    let traj = catalogue::quintic_from_origin(catalogue::GENERAL_TARGET, 0.3);
    catalogue::experiment("quintic", RobotParams::paper(), traj, t_end, 1e-3)
}

/// Worst defect of the energy balance `W = Delta(T + U) + E_d + E_f` over the output times, as a
/// fraction of the largest work, and the final `W`, `E_f` [J].
fn energy_defect(r: &Response) -> (f64, f64, f64) {
    let names = ["Ek_star", "Ek_sleeves", "Ek_sliders", "U"];
    let e = |k: usize| names.iter().map(|c| col(r, c)[k]).sum::<f64>();
    let (w, ef) = (col(r, "W"), col(r, "E_f"));
    let ed = r.column("E_d");
    let scale = w.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = (0..r.len())
        .map(|k| (w[k] - (e(k) - e(0)) - ed.map_or(0.0, |d| d[k]) - ef[k]).abs())
        .fold(0.0, f64::max);
    let n = r.len() - 1;
    (worst / scale, w[n], ef[n])
}

/// The energy balance with friction in the sleeves (both load models) and on the rails, in the
/// inverse problem: the work of the actuators (their forces include the rails' friction) is the
/// change of kinetic and strain energy plus the friction's dissipation `E_f` (its power
/// `F_f v_s` and `(Fc sign v + b v) v`, Eq. F7), to 1e-3 of the work.
#[test]
fn energy_balance_with_friction() {
    for model in ["normal", "edges"] {
        let mut exp = quintic(0.45);
        exp.friction = Some(friction(&format!(
            "mu = 0.3\nc = 0.5\nmodel = \"{model}\"\n[rails]\nFc = 0.5\nb = 2.0\n"
        )));
        let r = fem(&exp, &coarse(), SolveRequest::motion());
        let (defect, w, ef) = energy_defect(&r);
        let stuck: Vec<f64> = (1..=3)
            .map(|i| col(&r, &format!("stick{i}")).iter().sum::<f64>())
            .collect();
        eprintln!(
            "{model}: defect {defect:.2e} of the work, W {w:.4e} J, E_f {ef:.4e} J, stuck samples {stuck:?}, {:?}",
            r.friction
        );
        assert!(
            ef > 0.05 * w,
            "friction must be a real part of the balance: E_f {ef} J of W {w} J"
        );
        assert!(defect < 1e-3, "{model}: energy defect {defect:.3e} of the work");
    }
}

/// A force pulse on slider 1, `F0 sin(pi t / T)` [N] for `t < T`, zero after; nothing on the
/// other two.
struct Pulse {
    f0: f64,
    t_pulse: f64,
}

impl Pulse {
    fn at(&self, t: f64) -> f64 {
        if t < self.t_pulse {
            self.f0 * (std::f64::consts::PI * t / self.t_pulse).sin()
        } else {
            0.0
        }
    }
}

impl flexstar_drive::ActuatorLaw for Pulse {
    fn force(&self, t: f64, _s: [f64; 3], _v: [f64; 3]) -> Result<[f64; 3], flexstar_drive::DriveError> {
        Ok([self.at(t), 0.0, 0.0])
    }
    fn stiffness(&self) -> [f64; 3] {
        [0.0; 3]
    }
    fn damping(&self) -> [f64; 3] {
        [0.0; 3]
    }
}

/// The block on a rail with Coulomb friction `Fc` under [`Pulse`], in closed form: stuck until
/// `F0 sin(pi t / T) = Fc` at `t1`, then `m x'' = F(t) - Fc` while it slides, stuck again at
/// `t2` where its speed returns to zero (`F < Fc` there). Returns `t1`, `t2` [s] and the travel
/// `x(t2)` [m] (`t2` by bisection on the closed-form speed).
fn block_on_rail(m: f64, fc: f64, p: &Pulse) -> (f64, f64, f64) {
    use std::f64::consts::PI;
    let (f0, tp) = (p.f0, p.t_pulse);
    let t1 = tp / PI * (fc / f0).asin();
    let c1 = (PI * t1 / tp).cos();
    // speed and travel while the pulse lasts, then under Fc alone
    let v_in = |t: f64| (f0 * tp / PI * (c1 - (PI * t / tp).cos()) - fc * (t - t1)) / m;
    let x_in = |t: f64| {
        (f0 * tp / PI * (c1 * (t - t1) - tp / PI * ((PI * t / tp).sin() - (PI * t1 / tp).sin()))
            - 0.5 * fc * (t - t1).powi(2))
            / m
    };
    let v = |t: f64| if t <= tp { v_in(t) } else { v_in(tp) - fc / m * (t - tp) };
    let x = |t: f64| {
        if t <= tp {
            x_in(t)
        } else {
            x_in(tp) + v_in(tp) * (t - tp) - 0.5 * fc / m * (t - tp).powi(2)
        }
    };
    // the speed rises, then falls to zero once: bisect on its sign after its peak (t = tp - t1)
    let (mut lo, mut hi) = (tp - t1, tp + v_in(tp).max(0.0) * m / fc + 1e-9);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if v(mid) > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    (t1, lo, x(lo))
}

/// A block on a rail: slider 1 (500 kg, `Fc = 1000 N`) pushed by a force pulse of 2000 N over
/// 0.2 s, sliders 2 and 3 held by their rails (`Fc = 1e5 N`), the star stiff (EI x 100) and
/// frictionless in its sleeves, so that it weighs 0.07 % of the slider. The FEM's direct run
/// against the closed-form stick-slip of [`block_on_rail`]: the slider breaks loose and sticks
/// again within one step of the closed form's `t1`, `t2`, travels the closed form's distance to
/// 0.2 % (measured: 0.05 %) and its rail dissipates `Fc` times the travel.
#[test]
fn a_slider_on_its_rail_sticks_and_slips_as_a_block_with_coulomb_friction() {
    let (m, fc, h) = (500.0, 1000.0, 2.5e-4);
    let pulse = Pulse {
        f0: 2000.0,
        t_pulse: 0.2,
    };
    let mut robot = RobotParams::paper();
    robot.i *= 100.0;
    robot.mpp_mpa = m;
    let traj = flexstar_model::Trajectory::Polynomial {
        s1: vec![0.0],
        s2: vec![0.0],
        s3: vec![0.0],
    };
    let mut exp = catalogue::experiment("block", robot, traj, 0.35, h);
    exp.friction = Some(friction("[rails]\nFc = [1000.0, 1e5, 1e5]\n"));
    let settings = FemSettings {
        dt: Some(h),
        ..coarse()
    };
    let r = fem(&exp, &settings, SolveRequest::law(&pulse));
    let (t1, t2, travel) = block_on_rail(m, fc, &pulse);
    let (s1, sd1) = (col(&r, "s1"), col(&r, "sd1"));
    let first = (0..r.len()).find(|&k| s1[k] != s1[0]).expect("the slider moves");
    let last = (0..r.len()).rev().find(|&k| sd1[k] != 0.0).expect("the slider moves");
    let moved = s1[r.len() - 1] - s1[0];
    let others = (1..3).map(|i| {
        col(&r, &format!("s{}", i + 1))
            .iter()
            .map(|s| s.abs())
            .fold(0.0, f64::max)
    });
    let held = others.fold(0.0, f64::max);
    eprintln!(
        "block: breaks loose at {:.5} s (closed form {t1:.5} s), sticks after {:.5} s (closed form {t2:.5} s), \
         travels {moved:.6e} m (closed form {travel:.6e} m, {:.2e}), sliders 2, 3 within {held:.1e} m, rails {:?}",
        r.t[first],
        r.t[last],
        moved / travel - 1.0,
        r.friction
    );
    assert!(
        (r.t[first] - t1).abs() <= h * 1.001,
        "breaks loose at {} s, closed form {t1} s",
        r.t[first]
    );
    // the last moving sample is the step in which the speed crosses zero
    assert!(
        (r.t[last] - t2).abs() <= h * 1.001,
        "sticks at {} s, closed form {t2} s",
        r.t[last]
    );
    assert!(
        (moved / travel - 1.0).abs() < 2e-3,
        "travel {moved} m, closed form {travel} m"
    );
    // the rail dissipated Fc times the travel (Eq. F7 at constant Fc)
    let dissipated = r.friction.unwrap().rails_dissipated_j;
    assert!(
        (dissipated / (fc * moved) - 1.0).abs() < 1e-3,
        "dissipated {dissipated} J"
    );
    assert!(held == 0.0, "sliders 2 and 3 must stay stuck: {held} m");
    let stuck = r.friction.unwrap().rails_stuck_s[0];
    assert!(
        (stuck - (0.35 - (t2 - t1))).abs() <= 2.0 * h + 1e-9,
        "slider 1 stuck {stuck} s"
    );
}
