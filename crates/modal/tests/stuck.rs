//! The linear systems of a robot whose sleeves stick (`docs/modes.md`, stuck sleeves: Eqs. S1-S3),
//! each against a reference independent of the code under test: the other solver (the AMM's
//! stick springs of Eq. S1 against the FEM's held contact coordinate of Eq. S2), Rayleigh's
//! theorem on an added constraint (mode by mode against the sliding system), and the clamped
//! cantilever of an overhang.

use flexstar_modal::analysis::{modal, modal_held, Modal};
use flexstar_modal::linear::{linearize_with, Holding, LinearSettings};
use flexstar_modal::pose::pose_from_task;
use flexstar_model::{Experiment, RestPose, Sleeves, Sliders};

const MOTION: &str = "name = \"t\"\n[time]\nt_end = 0.5\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\n\
                      s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n";

fn experiment(extra: &str) -> Experiment {
    Experiment::from_toml_str(&format!("{MOTION}{extra}"), std::path::Path::new("t.toml")).unwrap()
}

fn pose(exp: &Experiment, [gx, gy, th]: [f64; 3]) -> RestPose {
    pose_from_task(&flexstar_modal::robot(exp).unwrap(), gx, gy, th).unwrap()
}

/// Two off-centre turned poses of the paper's robot (no symmetry to hide an error).
const POSES: [[f64; 3]; 2] = [[0.03, -0.02, 0.1], [-0.06, 0.04, -0.12]];

/// AMM (enriched, N = 60, the stick springs `EA / xp` of Eq. S1) against the FEM (300 elements,
/// axially elastic beams, `xi_c` held: Eq. S2), sleeves stuck, sliders locked and free: the first
/// six frequencies within 1 % (the tolerance of the sliding systems in `modal_checks.rs`).
#[test]
fn stuck_modes_of_the_amm_and_the_fem_agree() {
    let exp = experiment("");
    for p in POSES {
        let pose = pose(&exp, p);
        for sliders in [Sliders::Locked, Sliders::Free] {
            let m = modal_held(&exp, &pose, sliders, Sleeves::Stuck, 6).unwrap();
            assert_eq!((m.amm.rigid, m.fem.rigid), (0, 0), "stuck sleeves leave no rigid mode");
            for (mode, a, f, rel) in m.rows() {
                eprintln!(
                    "{p:?} {sliders:?} stuck mode {mode}: AMM {a:.5} Hz, FEM {f:.5} Hz, {:+.4} %",
                    100.0 * rel
                );
                assert!(
                    rel.abs() < 0.01,
                    "{p:?} {sliders:?} mode {mode}: AMM {a} Hz against FEM {f} Hz"
                );
            }
        }
    }
}

/// Rayleigh's theorem (Courant-Fischer): a constraint added (the FEM's row of Eq. S2) or a
/// stiffness added (the AMM's spring of Eq. S1, positive semi-definite) raises every eigenvalue,
/// `omega_k(stuck) >= omega_k(sliding)` mode by mode, the sliding system's rigid zeros included.
/// Checked in each solver at both poses and both holdings, to 1e-9 relative (round-off of the
/// eigensolvers); the stuck system also changes the spectrum (some mode moves by > 1 %).
#[test]
fn stuck_frequencies_are_at_least_the_sliding_ones_mode_by_mode() {
    let exp = experiment("");
    for p in POSES {
        let pose = pose(&exp, p);
        for sliders in [Sliders::Locked, Sliders::Free] {
            let sliding = modal(&exp, &pose, sliders, 9).unwrap();
            let stuck = modal_held(&exp, &pose, sliders, Sleeves::Stuck, 12).unwrap();
            for (name, a, b) in [
                ("AMM", &sliding.amm.freq_hz, &stuck.amm.freq_hz),
                ("FEM", &sliding.fem.freq_hz, &stuck.fem.freq_hz),
            ] {
                let mut moved: f64 = 0.0;
                for (k, (fs, fk)) in a.iter().zip(b).enumerate().take(12) {
                    eprintln!(
                        "{p:?} {sliders:?} {name} mode {}: sliding {fs:.5} Hz, stuck {fk:.5} Hz",
                        k + 1
                    );
                    assert!(
                        *fk >= fs * (1.0 - 1e-9),
                        "{name} {p:?} {sliders:?} mode {}: stuck {fk} < sliding {fs}",
                        k + 1
                    );
                    if *fs > 0.0 {
                        moved = moved.max(fk / fs - 1.0);
                    }
                }
                assert!(
                    moved > 0.01,
                    "{name} {p:?} {sliders:?}: sticking changed no mode by 1 % ({moved})"
                );
            }
        }
    }
}

/// A stuck sleeve's overhang against the clamped cantilever `f = (1.875^2 / (2 pi a^2)) sqrt(EI /
/// rho)`, `a = L - xp - Lp / 2` (the set-up of the FEM's time-domain check in
/// `crates/fem/tests/friction.rs`): a small base (d = 0.03 m) puts the sleeves 0.03 m from G, so the
/// short inner spans are far stiffer than the 0.455 m overhangs, and the first three modes of the
/// stuck star are the three overhangs' first modes. The sleeve's rotation is held by the short
/// span, which lowers the frequency by about `(1 + 3 xp / (4 a))^(-1/2)` = 0.976 (a cantilever on
/// the rotational spring `4 EI / xp`; G's own rotation and the sleeve's inertia change it
/// somewhat): each solver's f1..f3 within 5 % of the clamped cantilever and below it, and within
/// 1.5 % of the spring-corrected estimate (the FEM's time-domain check measured 0.973 and 0.997).
#[test]
fn a_stuck_overhang_is_a_clamped_cantilever() {
    let exp = experiment("[robot]\nd = 0.03\n");
    let pose = pose(&exp, [0.0, 0.0, 0.0]);
    let m: Modal = modal_held(&exp, &pose, Sliders::Locked, Sleeves::Stuck, 4).unwrap();
    let r = exp.robot;
    let xp = pose.xp[0];
    let a = r.l - xp - 0.5 * r.lp;
    let f_clamped = 1.875_104_068_711_961f64.powi(2) / (a * a) * (r.ei() / r.rho).sqrt() / (2.0 * std::f64::consts::PI);
    let spring = (1.0 + 3.0 * xp / (4.0 * a)).powf(-0.5);
    for (mode, fa, ff, _) in m.rows().into_iter().take(3) {
        for (name, f) in [("AMM", fa), ("FEM", ff)] {
            let ratio = f / f_clamped;
            eprintln!(
                "mode {mode} {name}: {f:.5} Hz, clamped cantilever {f_clamped:.5} Hz (a = {a:.4} m), ratio {ratio:.4}, to the spring-corrected {:.4}",
                ratio / spring
            );
            assert!(
                (0.95..=1.0).contains(&ratio),
                "mode {mode} {name}: {ratio} of the clamped cantilever"
            );
            assert!(
                (ratio / spring - 1.0).abs() < 0.015,
                "mode {mode} {name}: {} of the estimate",
                ratio / spring
            );
        }
    }
}

/// The linear model with stuck sleeves (free sliders, open loop): the eigenvalues of A are the
/// stuck modes' `+-i omega` (its frequencies are the FEM's within 1 %, the first test).
#[test]
fn linearize_takes_stuck_sleeves_with_free_sliders() {
    let exp = experiment("");
    let pose = pose(&exp, POSES[0]);
    let settings = LinearSettings {
        modes: 6,
        holding: Holding::Free,
        sleeves: Sleeves::Stuck,
    };
    let ss = linearize_with(&exp, &pose, &settings).unwrap();
    let fem = modal_held(&exp, &pose, Sliders::Free, Sleeves::Stuck, 6)
        .unwrap()
        .fem
        .freq_hz;
    assert_eq!(ss.modes.rigid, 0);
    assert_eq!(ss.a.rows(), 12);
    let a = ss.a.to_dense();
    // A = [0 I; -Omega^2 0] without damping: omega_k^2 = -A[6 + k][k]
    for k in 0..6 {
        let f = (-a[[6 + k, k]]).sqrt() / (2.0 * std::f64::consts::PI);
        eprintln!("linear stuck mode {}: {f:.5} Hz, FEM {:.5} Hz", k + 1, fem[k]);
        assert!((f / fem[k] - 1.0).abs() < 0.01);
    }
}

/// Locked sliders with stuck sleeves (Eqs. S4-S6): a slider held by its drive is the limit of a
/// servo of unbounded stiffness, so the deflection a unit slider displacement leaves at rest,
/// `H (R - R_rig)` of Eq. S6 (the static shapes of Eq. S4, a saddle-point solve), must be the
/// free stuck robot's static deflection with that slider displaced and the others held, from its
/// modes and eigenvalues instead, `q_j = Phi Omega^-2 Phi^T S^T (S Phi Omega^-2 Phi^T S^T)^-1 e_j`
/// with every mode of the free system (the spectral form of K^-1 on the constraints), less the
/// sliding robot's rigid motion (from its rigid modes), on the deflection rows; to 1e-6 (the
/// rigid modes' own accuracy, about 1e-7: `static_shapes.rs`' unit test). Also: A's frequencies
/// are the FEM's locked stuck ones within 1 %, the sliders are states (`s1..s3`, `sd1..sd3`)
/// integrating the inputs `sdd1..sdd3`, and a unit slider displacement leaves a deflection (not
/// nil: the sleeves hold their material points). Both poses.
#[test]
fn locked_sliders_strain_the_stuck_star_as_a_stiff_servo_would() {
    let exp = experiment("");
    for p in POSES {
        let pose = pose(&exp, p);
        let locked = linearize_with(
            &exp,
            &pose,
            &LinearSettings {
                modes: 6,
                holding: Holding::Locked,
                sleeves: Sleeves::Stuck,
            },
        )
        .unwrap();
        let nr = 6;
        assert_eq!(locked.a.rows(), 2 * nr + 6);
        let names: Vec<&str> = locked.states.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(&names[2 * nr..], ["s1", "s2", "s3", "sd1", "sd2", "sd3"]);
        let (a, b, c) = (locked.a.to_dense(), locked.b.to_dense(), locked.c.to_dense());
        for i in 0..3 {
            assert_eq!(a[[2 * nr + i, 2 * nr + 3 + i]], 1.0);
            assert_eq!(b[[2 * nr + 3 + i, i]], 1.0);
        }
        let fem = modal_held(&exp, &pose, Sliders::Locked, Sleeves::Stuck, nr)
            .unwrap()
            .fem
            .freq_hz;
        for k in 0..nr {
            let f = (-a[[nr + k, k]]).sqrt() / (2.0 * std::f64::consts::PI);
            assert!(
                (f / fem[k] - 1.0).abs() < 0.01,
                "mode {}: {f} Hz, FEM {} Hz",
                k + 1,
                fem[k]
            );
        }
        // the free stuck robot with every mode its AMM basis has: the static deflection of the
        // sliders' unit displacements, q_j = sum_k phi_k (S phi_k)^T / omega_k^2 (S Omega^-2 S^T)^-1
        let model = flexstar_modal::analysis::amm_pose_model(&exp).unwrap();
        let stuck = model.clone().with_sleeves(Sleeves::Stuck);
        let sys = stuck.system_at(&pose, Sliders::Free);
        let free = stuck.modes_at(&pose, Sliders::Free, sys.n - sys.rows).unwrap();
        let (phi, omega2) = (&free.shapes, &free.omega2);
        let nf = phi.len();
        let si = [0, 1, 2].map(|i| sys.slider_index(i).unwrap());
        let gram =
            nalgebra::Matrix3::from_fn(|i, j| (0..nf).map(|k| phi[k][si[i]] * phi[k][si[j]] / omega2[k]).sum::<f64>());
        let gram_inv = gram.try_inverse().unwrap();
        let static_shape = |j: usize| -> Vec<f64> {
            let weights: Vec<f64> = (0..nf)
                .map(|k| (0..3).map(|i| phi[k][si[i]] / omega2[k] * gram_inv[(i, j)]).sum())
                .collect();
            (0..sys.n)
                .map(|a| (0..nf).map(|k| phi[k][a] * weights[k]).sum())
                .collect()
        };
        // less the rigid motion of the sliding robot (its rigid modes), on the deflection rows
        let sliding = model
            .with_sleeves(Sleeves::Sliding)
            .modes_at(&pose, Sliders::Free, 1)
            .unwrap();
        let rigid = &sliding.shapes[..3];
        let rs = nalgebra::Matrix3::from_fn(|i, k| rigid[k][si[i]]);
        let rs_inv = rs.try_inverse().unwrap();
        let robot = flexstar_modal::robot(&exp).unwrap();
        let mut worst = 0.0f64;
        let mut largest = 0.0f64;
        for j in 0..3 {
            let q = static_shape(j);
            let deflection: Vec<f64> = (0..sys.n)
                .map(|a| q[a] - (0..3).map(|k| rigid[k][a] * rs_inv[(k, j)]).sum::<f64>())
                .collect();
            for (out, (beam, x)) in (0..3)
                .map(|i| (i, robot.beams()[i].length))
                .chain((0..3).map(|i| (i, 0.0)))
                .enumerate()
            {
                let spectral: f64 = sys
                    .deflection_row(beam, x)
                    .iter()
                    .zip(&deflection)
                    .map(|(h, d)| h * d)
                    .sum();
                let from_static_shapes = c[[out, 2 * nr + j]];
                largest = largest.max(spectral.abs());
                worst = worst.max((from_static_shapes - spectral).abs());
            }
        }
        eprintln!(
            "pose {p:?}: {nf} free stuck modes; deflection per unit slider displacement up to {largest:.4e}, \
             static shapes against the spectral form {worst:.3e}"
        );
        assert!(largest > 1e-3, "a unit slider displacement must strain the stuck star");
        assert!(worst <= 1e-6 * largest, "{worst:e} of {largest:e}");
    }
}
