//! Linear state-space model of the small motion about a pose with free sliders (issue 11):
//!
//! ```text
//! x' = A x + B u,   y = C x + D u
//! ```
//! built from the AMM's modes at the pose (sliders free, [`flexstar_amm::pose_modes`]) in modal
//! coordinates: `x = [eta; eta']` with `q = Phi eta` (mass-normalised shapes, the three rigid modes
//! first, then [`ELASTIC_MODES`] elastic ones), so `A = [[0, I], [-Omega^2, 0]]`,
//! `B = [0; Phi^T F]`, `C = [H Phi, 0]`, `D = 0`.
//! Inputs: the actuator forces Fa_1..Fa_3 [N] on the sliders along `+u_i` (Eq. 33).
//! Outputs (docs/conventions.md): s_1..s_3 [m] (from the pose), the tip deflections
//! `w_i(L)` [m] and `w_iG` [m], both relative to the rigid star the sliders hold (the rigid
//! kinematics' Jacobian at the pose removes the rigid part).

use std::path::Path;

use flexstar_amm::pose_modes::PoseModes;
use flexstar_kinematics::RigidState;
use flexstar_model::output::write_atomically;
use flexstar_model::{Experiment, RestPose, Sliders};
use num_dual::Dual2;
use sprs::{CsMat, TriMat};

use crate::analysis::amm_modes_per_beam;
use crate::ModalError;

/// Elastic modes kept in the state-space model (after the three rigid ones).
pub const ELASTIC_MODES: usize = 20;

/// Names and units of the inputs.
pub const INPUTS: [(&str, &str); 3] = [("Fa1", "N"), ("Fa2", "N"), ("Fa3", "N")];
/// Names and units of the outputs.
pub const OUTPUTS: [(&str, &str); 9] = [
    ("s1", "m"),
    ("s2", "m"),
    ("s3", "m"),
    ("w1_tip", "m"),
    ("w2_tip", "m"),
    ("w3_tip", "m"),
    ("w1G", "m"),
    ("w2G", "m"),
    ("w3G", "m"),
];

/// The state-space model and what it was built from.
pub struct StateSpace {
    pub a: CsMat<f64>,
    pub b: CsMat<f64>,
    pub c: CsMat<f64>,
    pub d: CsMat<f64>,
    /// The modal analysis (sliders free) behind it.
    pub modes: PoseModes,
    pub pose: RestPose,
}

/// Derivatives of the rigid star (G [m], theta [rad]) with respect to s_j at the pose.
fn rigid_jacobian(exp: &Experiment, pose: &RestPose) -> Result<[[f64; 3]; 3], ModalError> {
    let mut jac = [[0.0; 3]; 3];
    for (j, _) in pose.s.iter().enumerate() {
        let s = [0, 1, 2].map(|i| Dual2::new(pose.s[i], if i == j { 1.0 } else { 0.0 }, 0.0));
        let st = RigidState::from_actuators(&exp.robot, s, 0.0).map_err(|e| ModalError::Infeasible(e.to_string()))?;
        jac[0][j] = st.g[0].d1;
        jac[1][j] = st.g[1].d1;
        jac[2][j] = st.theta.d1;
    }
    Ok(jac)
}

fn dense_to_cs(rows: usize, cols: usize, f: impl Fn(usize, usize) -> f64) -> CsMat<f64> {
    let mut t = TriMat::new((rows, cols));
    for r in 0..rows {
        for c in 0..cols {
            let v = f(r, c);
            if v != 0.0 {
                t.add_triplet(r, c, v);
            }
        }
    }
    t.to_csr()
}

/// The linear model about `pose` (sliders free).
pub fn linearize(exp: &Experiment, pose: &RestPose) -> Result<StateSpace, ModalError> {
    let modes = flexstar_amm::pose_modes::pose_modes(
        &exp.robot,
        pose,
        Sliders::Free,
        crate::analysis::amm_basis(exp).0,
        amm_modes_per_beam(exp),
        ELASTIC_MODES,
    )?;
    let sys = &modes.system;
    let nr = modes.shapes.len();
    let jac = rigid_jacobian(exp, pose)?;
    let l = exp.robot.l;
    // output rows H (9 x n) on the AMM coordinates
    let mut h = vec![vec![0.0; sys.n]; 9];
    for i in 0..3 {
        let si = sys.slider_index(i).expect("sliders free");
        h[i][si] = 1.0;
        let ew = flexstar_model::geometry::e_w(i, pose.theta);
        for (row, x, lever) in [(3 + i, l, l), (6 + i, 0.0, 0.0)] {
            let dr = sys.deflection_row(i, x);
            for (hv, v) in h[row].iter_mut().zip(dr) {
                *hv += v;
            }
            for (j, ((jx, jy), jt)) in jac[0].iter().zip(&jac[1]).zip(&jac[2]).enumerate() {
                let s_j = sys.slider_index(j).expect("sliders free");
                h[row][s_j] -= jx * ew[0] + jy * ew[1] + lever * jt;
            }
        }
    }
    let phi = &modes.shapes;
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let hphi: Vec<Vec<f64>> = h.iter().map(|r| phi.iter().map(|p| dot(r, p)).collect()).collect();
    let phit_f: Vec<[f64; 3]> = phi
        .iter()
        .map(|p| [0, 1, 2].map(|i| p[sys.slider_index(i).expect("sliders free")]))
        .collect();
    let n = 2 * nr;
    let a = dense_to_cs(n, n, |r, c| {
        if r < nr {
            f64::from(u8::from(c == r + nr))
        } else if c == r - nr {
            -modes.omega2[c]
        } else {
            0.0
        }
    });
    let b = dense_to_cs(n, 3, |r, c| if r < nr { 0.0 } else { phit_f[r - nr][c] });
    let c = dense_to_cs(9, n, |r, c| if c < nr { hphi[r][c] } else { 0.0 });
    let d = TriMat::new((9, 3)).to_csr();
    Ok(StateSpace {
        a,
        b,
        c,
        d,
        modes,
        pose: *pose,
    })
}

/// Write one sparse matrix as a Matrix Market file (sprs; whole or not at all).
pub fn write_mtx(path: &Path, m: &CsMat<f64>) -> Result<(), ModalError> {
    write_atomically(path, |w| {
        sprs::io::write_matrix_market_to_bufwrite(w, m)?;
        Ok(())
    })?;
    Ok(())
}

/// Read a Matrix Market file back (sprs).
pub fn read_mtx(path: &Path) -> Result<CsMat<f64>, ModalError> {
    let t: TriMat<f64> = sprs::io::read_matrix_market(path)
        .map_err(|e| ModalError::Input(format!("{}: cannot read Matrix Market: {e}", path.display())))?;
    Ok(t.to_csr())
}

/// A dense row-major matrix as a sparse one (zeros dropped).
pub fn dense(rows: usize, cols: usize, v: &[f64]) -> CsMat<f64> {
    dense_to_cs(rows, cols, |r, c| v[r * cols + c])
}

/// Write `dir/linear/`: A, B, C, D, statespace.json, and the FEM's M, K, Phi_q at the pose
/// (sliders free). Everything is computed before the first file is written, and the files are
/// published as one set ([`flexstar_model::run_set::RunSet`]).
pub fn write_linear(dir: &Path, exp: &Experiment, ss: &StateSpace) -> Result<(), ModalError> {
    let fem = flexstar_fem::pose_modes::pose_system(&exp.robot, &ss.pose, Sliders::Free, exp.fem.elements)?;
    let (fm, fk, fc) = (
        dense(fem.n, fem.n, &fem.m),
        dense(fem.n, fem.n, &fem.k),
        dense(fem.rows, fem.n, &fem.c),
    );
    let json = serde_json::json!({
        "description": "continuous-time state-space model x' = A x + B u, y = C x + D u of the small motion about the pose, sliders free (flexstar, AMM modal coordinates: x = [eta; eta'], rigid modes first)",
        "states": ss.a.rows(),
        "inputs": INPUTS.iter().map(|(n, u)| serde_json::json!({"name": n, "unit": u})).collect::<Vec<_>>(),
        "outputs": OUTPUTS.iter().map(|(n, u)| serde_json::json!({"name": n, "unit": u})).collect::<Vec<_>>(),
        "pose": {"Gx": ss.pose.g[0], "Gy": ss.pose.g[1], "theta": ss.pose.theta, "s": ss.pose.s, "xp": ss.pose.xp},
        "modal_frequencies_hz": ss.modes.freq_hz,
        "files": {"A": "A.mtx", "B": "B.mtx", "C": "C.mtx", "D": "D.mtx", "fem_mass": "M.mtx", "fem_stiffness": "K.mtx", "fem_constraint_jacobian": "Phi_q.mtx"},
        "fem": {"coordinates": fem.n, "constraints": fem.rows, "elements": exp.fem.elements},
    });
    // the seven matrices and the JSON are published together (issue 24)
    let mut set = flexstar_model::run_set::RunSet::begin(&dir.join("linear"))?;
    for (name, m) in [
        ("A", &ss.a),
        ("B", &ss.b),
        ("C", &ss.c),
        ("D", &ss.d),
        ("M", &fm),
        ("K", &fk),
        ("Phi_q", &fc),
    ] {
        set.file(&format!("{name}.mtx"), |w| {
            sprs::io::write_matrix_market_to_bufwrite(w, m)?;
            Ok(())
        })?;
    }
    set.text(
        "statespace.json",
        &serde_json::to_string_pretty(&json).expect("json of plain values"),
    )?;
    set.commit()?;
    Ok(())
}
