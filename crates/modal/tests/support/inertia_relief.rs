//! The reference of the linear model's elastic DC gain (test support, included by the modal
//! crate's tests with `#[path]`): the FEM's inertia-relief static deflection under a unit
//! actuator force, of the paper's robot or one as built.
//!
//! With free sliders a constant force accelerates the robot, so the static problem is the
//! inertia-relief one: the elastic deflection u under `f - M Phi_r Phi_r^T f` (the load less the
//! inertia of the rigid acceleration it causes), `Phi_q u = 0`, u M-orthogonal to the rigid
//! modes. The FEM (150 elements) is solved directly as one dense saddle-point system (faer LU),
//! with its own rigid modes, and the outputs are measured as the model defines them (Eq. M1 of
//! `docs/modes.md`): node displacement along beam i's own `e_wi` less the rigid star held by the
//! sliders' displacement (the rigid Jacobian by dual numbers, lever `L_i` at the tip).

use faer::linalg::solvers::Solve;
use flexstar_modal::linear::StateSpace;
use flexstar_model::{Robot, RobotGeometry, Sliders};

/// The largest difference [m/N] between the model's elastic DC gain
/// `sum_{j elastic} C_j B_j / omega_j^2` (unit `Fa_k` to the tips and `w_iG`, rows 3..9 of the
/// free model) and the FEM's inertia-relief deflection, and the largest FEM gain [m/N].
pub fn elastic_static_gain_error(robot: &Robot, ss: &StateSpace) -> (f64, f64) {
    let (a, b, c) = (ss.a.to_dense(), ss.b.to_dense(), ss.c.to_dense());
    let nr = ss.a.rows() / 2;
    let gain = |r: usize, k: usize| -> f64 { (3..nr).map(|j| c[[r, j]] * b[[nr + j, k]] / -a[[nr + j, j]]).sum() };
    let fem = flexstar_fem::pose_modes::pose_modes(robot, &ss.pose, Sliders::Free, 150, 1).unwrap();
    let sys = fem.system.to_dense();
    let (n, rows) = (sys.n, sys.rows);
    let mphi: Vec<Vec<f64>> = fem.shapes[..3]
        .iter()
        .map(|x| (0..n).map(|i| (0..n).map(|j| sys.m[i * n + j] * x[j]).sum()).collect())
        .collect();
    let size = n + rows + 3;
    let mut kkt = saddle_matrix(&sys, 3);
    for (q, mp) in mphi.iter().enumerate() {
        for j in 0..n {
            kkt[(n + rows + q, j)] = mp[j];
            kkt[(j, n + rows + q)] = mp[j];
        }
    }
    let lu = kkt.partial_piv_lu();
    // rigid Jacobian dG/ds, dtheta/ds at the pose (dual numbers), for the outputs
    let jac: Vec<[f64; 3]> = (0..3)
        .map(|k| {
            let s = [0, 1, 2].map(|i| num_dual::Dual2::new(ss.pose.s[i], if i == k { 1.0 } else { 0.0 }, 0.0));
            let st = flexstar_kinematics::RigidState::from_actuators(robot, s, 0.0).unwrap();
            [st.g[0].d1, st.g[1].d1, st.theta.d1]
        })
        .collect();
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for k in 0..3 {
        let sk = sys.slider_index(k).unwrap();
        let mut f = vec![0.0; n];
        f[sk] = 1.0;
        let mut rhs = faer::Mat::<f64>::zeros(size, 1);
        for i in 0..n {
            let relief: f64 = (0..3).map(|q| mphi[q][i] * fem.shapes[q][sk]).sum();
            rhs[(i, 0)] = f[i] - relief;
        }
        lu.solve_in_place(rhs.as_mut());
        let u: Vec<f64> = (0..n).map(|i| rhs[(i, 0)]).collect();
        let ds: Vec<f64> = (0..3).map(|j| u[sys.slider_index(j).unwrap()]).collect();
        for i in 0..3 {
            let ew = robot.e_w(i, ss.pose.theta);
            let rigid = |lever: f64| -> f64 {
                (0..3)
                    .map(|j| ds[j] * (jac[j][0] * ew[0] + jac[j][1] * ew[1] + lever * jac[j][2]))
                    .sum()
            };
            let tip = sys.deflections(&u, i)[sys.ne] - rigid(robot.beams()[i].length);
            let g = sys.deflections(&u, i)[0] - rigid(0.0);
            for (row, fem_v) in [(3 + i, tip), (6 + i, g)] {
                let lin = gain(row, k);
                eprintln!("Fa{} -> output {row}: linear {lin:.6e} m/N, FEM {fem_v:.6e} m/N", k + 1);
                worst = worst.max((lin - fem_v).abs());
                scale = scale.max(fem_v.abs());
            }
        }
    }
    (worst, scale)
}

/// The static saddle-point matrix `[[K, Phi_q^T], [Phi_q, 0]]` of a FEM system at a pose, with
/// `extra` further rows and columns left zero for the caller's own constraints.
pub fn saddle_matrix(sys: &flexstar_fem::pose_modes::PoseSystem, extra: usize) -> faer::Mat<f64> {
    let (n, rows) = (sys.n, sys.rows);
    let size = n + rows + extra;
    let mut kkt = faer::Mat::<f64>::zeros(size, size);
    for i in 0..n {
        for j in 0..n {
            kkt[(i, j)] = sys.k[i * n + j];
        }
    }
    for r in 0..rows {
        for j in 0..n {
            kkt[(n + r, j)] = sys.c[r * n + j];
            kkt[(j, n + r)] = sys.c[r * n + j];
        }
    }
    kkt
}
