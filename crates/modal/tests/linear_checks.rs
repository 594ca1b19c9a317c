//! Checks of the linear model (A, B, C; `docs/modes.md`) against references independent of it: the FEM's
//! modal analysis (eigenvalues of A), the rigid robot's mass matrix from the drive crate's
//! forward dynamics (the rigid modes' residue of B and C).

use crate::rigid_forward;

use crate::inertia_relief;

use flexstar_modal::linear::{linearize, StateSpace, ELASTIC_MODES};
use flexstar_modal::pose::pose_from_task;
use flexstar_model::{Experiment, Sliders};

fn paper() -> Experiment {
    let text = "name = \"t\"\n[time]\nt_end = 0.5\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\ns1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n";
    Experiment::from_toml_str(text, std::path::Path::new("t.toml")).unwrap()
}

fn to_faer(m: &sprs::CsMat<f64>) -> faer::Mat<f64> {
    let d = m.to_dense();
    faer::Mat::from_fn(m.rows(), m.cols(), |r, c| d[[r, c]])
}

/// An off-centre turned pose (all three sliders and xp distinct, no symmetry to hide an error).
fn linear_model(exp: &Experiment) -> StateSpace {
    let pose = pose_from_task(&flexstar_modal::robot(exp).unwrap(), 0.03, -0.02, 0.1).unwrap();
    linearize(exp, &pose).unwrap()
}

/// The eigenvalues of A, computed by faer's general (unsymmetric) eigensolver, are six zeros (the
/// three rigid modes, each a 2 x 2 Jordan block) and `+- i omega` with omega = 2 pi f of the
/// sliders-free modal analysis: of the AMM it is built from (to round-off; this checks the
/// assembly of A), and of the FEM (independent model, 300 elements: within 1 %, the AMM-FEM
/// agreement of the locked-slider test, on the first six elastic modes).
#[test]
fn eigenvalues_of_a_are_the_free_slider_frequencies_of_amm_and_fem() {
    let exp = paper();
    let ss = linear_model(&exp);
    let ev = to_faer(&ss.a).eigenvalues().unwrap();
    let nr = ss.a.rows() / 2;
    assert_eq!(nr, 3 + ELASTIC_MODES);
    let wmax = ev.iter().map(|z| z.im.abs()).fold(0.0, f64::max);
    // a 2 x 2 Jordan block at 0 moves by sqrt(eps |A|) under round-off
    let zero_tol = (f64::EPSILON * wmax * wmax).sqrt() * 10.0;
    let zeros = ev.iter().filter(|z| z.re.hypot(z.im) < zero_tol).count();
    assert_eq!(zeros, 6, "zero tolerance {zero_tol:e}: {ev:?}");
    let mut w: Vec<f64> = ev.iter().filter(|z| z.im > zero_tol).map(|z| z.im).collect();
    w.sort_by(f64::total_cmp);
    assert_eq!(w.len(), ELASTIC_MODES);
    for z in &ev {
        assert!(z.re.abs() < 1e-9 * wmax, "undamped model: {z:?}");
    }
    let two_pi = 2.0 * std::f64::consts::PI;
    for (j, wj) in w.iter().enumerate() {
        let f = ss.modes.freq_hz[3 + j];
        assert!((wj / (two_pi * f) - 1.0).abs() < 1e-9, "mode {j}: {wj} vs AMM {f} Hz");
    }
    let fem = flexstar_fem::pose_modes::pose_modes(&exp.robot, &ss.pose, Sliders::Free, 300, 6).unwrap();
    assert_eq!(fem.rigid, 3);
    for (j, (wj, f)) in w.iter().zip(&fem.freq_hz[3..]).enumerate() {
        let rel = wj / (two_pi * f) - 1.0;
        assert!(
            rel.abs() < 0.01,
            "elastic mode {}: A gives {} Hz, FEM {f} Hz",
            j + 1,
            wj / two_pi
        );
    }
}

/// The rigid part of the model against the rigid robot: at low frequency the sliders answer the
/// actuator forces as a rigid body, `s'' = M_r^-1 Fa`. In modal form
/// `s(p) = sum_j C_s,j B_j Fa / (p^2 + omega_j^2)`, so the residue of the three 0 Hz modes in
/// `p^2 s / Fa` is `sum_{j rigid} C[s, j] B[nr + j, :]`; the reference `M_r^-1` comes from
/// `rigid_forward::rigid_acceleration` (tests/support) (virtual power with the exact Fermat-point
/// Jacobians, no modes) with zero velocity, one unit force at a time.
#[test]
fn rigid_residue_is_the_inverse_rigid_mass_matrix() {
    let exp = paper();
    let ss = linear_model(&exp);
    let (b, c) = (ss.b.to_dense(), ss.c.to_dense());
    let nr = ss.a.rows() / 2;
    let mut scale = 0.0f64;
    let mut worst = 0.0f64;
    for k in 0..3 {
        let mut fa = [0.0; 3];
        fa[k] = 1.0;
        let reference = rigid_forward::rigid_acceleration(&exp.robot, ss.pose.s, [0.0; 3], fa).unwrap();
        for (i, r) in reference.iter().enumerate() {
            let residue: f64 = (0..3).map(|j| c[[i, j]] * b[[nr + j, k]]).sum();
            scale = scale.max(r.abs());
            worst = worst.max((residue - r).abs());
            eprintln!("M_r^-1[{i}][{k}]: residue {residue:.12e} rigid {r:.12e}");
        }
    }
    assert!(scale > 1.0, "M_r^-1 of a robot of a few hundred grams: {scale}");
    // measured: 5.6e-9 relative (the rigid modes' subspace from the shifted inverse iteration)
    assert!(worst < 1e-7 * scale, "largest difference {worst:e} of {scale:e}");
}

/// A smooth force pulse on slider 1: `F0 sin^2(pi t / tp)` for `t < tp`, then zero.
struct Pulse {
    f0: f64,
    tp: f64,
}

impl Pulse {
    fn at(&self, t: f64) -> [f64; 3] {
        let f = if t < self.tp {
            self.f0 * (std::f64::consts::PI * t / self.tp).sin().powi(2)
        } else {
            0.0
        };
        [f, 0.0, 0.0]
    }
}

impl flexstar_drive::ActuatorLaw for Pulse {
    fn force(&self, t: f64, _s: [f64; 3], _v: [f64; 3]) -> Result<[f64; 3], flexstar_drive::DriveError> {
        Ok(self.at(t))
    }
    fn stiffness(&self) -> [f64; 3] {
        [0.0; 3]
    }
    fn damping(&self) -> [f64; 3] {
        [0.0; 3]
    }
}

/// The linear model's response to a small force pulse against the nonlinear direct AMM run
/// (`flexstar_amm::solve` under a law, `docs/amm.md` section 10: sliders free under prescribed forces, exact
/// Fermat-point kinematics, generalized-alpha in time, same N): EVP (Eq. 45) of the slider
/// displacements and of the tip and G deflections within 1 %. The linear response is integrated
/// here mode by mode (`eta'' + omega^2 eta = B eta-row . Fa`, RK4 at 1e-5 s) from A, B, C alone.
/// A 0.02 N, 20 ms pulse on slider 1 (its spectrum reaches the first six elastic modes) moves
/// the robot by ~0.1 mm in 0.3 s: small motion, where the two must agree. Measured: EVP 0.002 %
/// (s1) to 0.09 % (s3, w3G); tips 0.03-0.06 %.
#[test]
fn pulse_response_matches_the_nonlinear_direct_run() {
    let mut exp = paper();
    let ss = linear_model(&exp);
    let s0 = ss.pose.s;
    exp.trajectory = flexstar_model::Trajectory::Polynomial {
        s1: vec![s0[0]],
        s2: vec![s0[1]],
        s3: vec![s0[2]],
    };
    exp.time.t_end = 0.3;
    exp.time.dt_out = 1e-3;
    let pulse = Pulse { f0: 0.02, tp: 0.02 };
    let settings = flexstar_model::AmmSettings {
        modes: Some(flexstar_modal::analysis::amm_modes_per_beam(&exp)),
        tol: None,
        ..exp.amm.clone()
    };
    let problem = exp.problem().unwrap();
    let direct = flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::law(&pulse))
        .map(|s| s.response)
        .unwrap();
    // linear response, modal coordinates
    let (a, b, c) = (ss.a.to_dense(), ss.b.to_dense(), ss.c.to_dense());
    let nr = ss.a.rows() / 2;
    let omega2: Vec<f64> = (0..nr).map(|j| -a[[nr + j, j]]).collect();
    let h = 1e-5;
    let mut eta = vec![[0.0f64; 2]; nr];
    let rhs = |t: f64, j: usize, e: [f64; 2]| -> [f64; 2] {
        let fa = pulse.at(t);
        let f: f64 = (0..3).map(|k| b[[nr + j, k]] * fa[k]).sum();
        [e[1], f - omega2[j] * e[0]]
    };
    let mut outputs: Vec<[f64; 9]> = Vec::new();
    let steps_per_out = (exp.time.dt_out / h).round() as usize;
    let mut t = 0.0;
    for k in 0..direct.len() {
        if k > 0 {
            for _ in 0..steps_per_out {
                for (j, e) in eta.iter_mut().enumerate() {
                    let k1 = rhs(t, j, *e);
                    let k2 = rhs(t + h / 2.0, j, [e[0] + h / 2.0 * k1[0], e[1] + h / 2.0 * k1[1]]);
                    let k3 = rhs(t + h / 2.0, j, [e[0] + h / 2.0 * k2[0], e[1] + h / 2.0 * k2[1]]);
                    let k4 = rhs(t + h, j, [e[0] + h * k3[0], e[1] + h * k3[1]]);
                    for d in 0..2 {
                        e[d] += h / 6.0 * (k1[d] + 2.0 * k2[d] + 2.0 * k3[d] + k4[d]);
                    }
                }
                t += h;
            }
        }
        outputs.push(std::array::from_fn(|r| (0..nr).map(|j| c[[r, j]] * eta[j][0]).sum()));
    }
    let lin = |r: usize| outputs.iter().map(|o| o[r]).collect::<Vec<f64>>();
    let mut checked = Vec::new();
    for i in 0..3 {
        let name = ["s1", "s2", "s3"][i];
        let ds: Vec<f64> = direct.column(name).unwrap().iter().map(|s| s - s0[i]).collect();
        checked.push((name.to_string(), lin(i), ds));
        checked.push((format!("w{}_tip", i + 1), lin(3 + i), direct.w_tip[i].clone()));
        checked.push((format!("w{}G", i + 1), lin(6 + i), direct.w_g[i].clone()));
    }
    for (name, l, d) in &checked {
        let e = flexstar_numerics::measures::evp(&direct.t, l, d).unwrap();
        let peak = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        eprintln!("{name}: EVP {e:.3} % (peak {peak:.3e} m)");
        assert!(
            peak > 0.0 && e <= 1.0,
            "{name}: EVP {e} % of the linear model against the direct run"
        );
    }
}

/// C's tip and G rows against the FEM's static deflection: the elastic DC gain of the linear
/// model, `sum_{j elastic} C_j B_j / omega_j^2`, against the FEM's inertia-relief deflection
/// (tests/support/inertia_relief.rs: 150 elements, one dense saddle-point system, the outputs
/// measured as in the model).
#[test]
fn elastic_static_gain_matches_the_fem_inertia_relief_deflection() {
    let exp = paper();
    let ss = linear_model(&exp);
    let (worst, scale) = inertia_relief::elastic_static_gain_error(&flexstar_modal::robot(&exp).unwrap(), &ss);
    assert!(scale > 0.0);
    // measured: 0.11 % of the largest gain (2.7e-3 m/N); entry by entry 0.4 % at most
    assert!(
        worst < 5e-3 * scale,
        "largest difference {worst:e} m/N of {scale:e} m/N"
    );
}
