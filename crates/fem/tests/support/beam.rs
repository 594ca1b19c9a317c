//! One straight beam of the star's cross-section and length, meshed with the co-rotational
//! element of [`flexstar_fem::element`]: the element's self-checks (natural frequencies of the
//! linearised element, large-rotation statics). The star model uses the very same element code.

use nalgebra::{DMatrix, DVector};

use flexstar_model::RobotParams;

use flexstar_fem::element::{Element, ElementState};
use flexstar_fem::{FemError, NewtonFailure};

/// Boundary conditions of a single beam for the frequency check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BeamSupport {
    /// Clamped at x = 0, free at x = L.
    ClampedFree,
    /// Free at both ends.
    FreeFree,
}

/// Elements of a straight beam of length `l` along +X from the origin, nodes 0..=n.
fn straight_elements(l: f64, n: usize) -> Vec<Element> {
    (0..n)
        .map(|k| Element {
            nodes: [k, k + 1],
            l0: l / n as f64,
            c0: 1.0,
            s0: 0.0,
        })
        .collect()
}

/// Initial DOFs `[x, y, phi]` per node of the straight beam.
fn straight_dofs(l: f64, n: usize) -> Vec<f64> {
    let mut q = vec![0.0; 3 * (n + 1)];
    for k in 0..=n {
        q[3 * k] = l * k as f64 / n as f64;
    }
    q
}

fn element_dofs(q: &[f64], el: &Element) -> [f64; 6] {
    let (a, b) = (3 * el.nodes[0], 3 * el.nodes[1]);
    [q[a], q[a + 1], q[a + 2], q[b], q[b + 1], q[b + 2]]
}

fn scatter(mat: &mut DMatrix<f64>, el: &Element, k: &[[f64; 6]; 6]) {
    let idx = |j: usize| 3 * el.nodes[j / 3] + j % 3;
    for i in 0..6 {
        for j in 0..6 {
            mat[(idx(i), idx(j))] += k[i][j];
        }
    }
}

fn check_elements(elements: usize) -> Result<(), FemError> {
    if elements == 0 || elements > 2000 {
        return Err(FemError::Input(format!(
            "need 1 <= elements <= 2000 for a single beam, got {elements}"
        )));
    }
    Ok(())
}

/// The first `count` bending natural frequencies [rad/s] of one beam (length `params.l`, EI, EA,
/// rho of `params`) meshed with `elements` co-rotational elements, linearised about the straight
/// stress-free state: the generalized eigenproblem `K phi = omega^2 M phi` with the consistent
/// mass of the element's cubic interpolation. Rigid-body modes (omega = 0) and axial modes
/// (no transverse motion) are skipped. Compare with `(beta L)^2 sqrt(EI / (rho L^4))`.
pub fn bending_frequencies(
    params: &RobotParams,
    elements: usize,
    support: BeamSupport,
    count: usize,
) -> Result<Vec<f64>, FemError> {
    check_elements(elements)?;
    let els = straight_elements(params.l, elements);
    let q = straight_dofs(params.l, elements);
    let n = q.len();
    let (mut k, mut m) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
    for el in &els {
        let st = ElementState::new(el, &element_dofs(&q, el));
        scatter(&mut k, el, &st.internal(params.ea(), params.ei()).1);
        scatter(&mut m, el, &st.inertia(params.rho, &[0.0; 6]).1);
    }
    let free: Vec<usize> = match support {
        BeamSupport::ClampedFree => (3..n).collect(),
        BeamSupport::FreeFree => (0..n).collect(),
    };
    let k = k.select_rows(&free).select_columns(&free);
    let m = m.select_rows(&free).select_columns(&free);
    let chol = m
        .clone()
        .cholesky()
        .ok_or_else(|| FemError::Input("mass matrix not positive definite".into()))?;
    // C = L^-1 K L^-T, symmetric
    let linv = chol
        .l()
        .try_inverse()
        .ok_or_else(|| FemError::Input("singular Cholesky factor".into()))?;
    let c = &linv * &k * linv.transpose();
    let c = (&c + c.transpose()) * 0.5;
    let eig = c.symmetric_eigen();
    let mut modes: Vec<(f64, DVector<f64>)> = eig
        .eigenvalues
        .iter()
        .zip(eig.eigenvectors.column_iter())
        .map(|(&lam, y)| (lam, linv.transpose() * y))
        .collect();
    modes.sort_by(|a, b| a.0.total_cmp(&b.0));
    let scale = params.ei() / (params.rho * params.l.powi(4));
    let mut out = Vec::with_capacity(count);
    for (lam, phi) in modes {
        if lam < 1e-2 * scale {
            continue; // rigid-body mode
        }
        // transverse content: y components against x components (nodes are along X)
        let (mut ty, mut tx) = (0.0, 0.0);
        for (r, &dof) in free.iter().enumerate() {
            match dof % 3 {
                0 => tx += phi[r] * phi[r],
                1 => ty += phi[r] * phi[r],
                _ => {}
            }
        }
        if ty > tx {
            out.push(lam.sqrt());
            if out.len() == count {
                break;
            }
        }
    }
    Ok(out)
}

/// Static large-rotation benchmark: a cantilever (clamped at the origin, along +X) loaded by an
/// end moment `moment` [N m], applied in `increments` equal load steps, each solved by Newton's
/// method with the exact co-rotational tangent. Returns the final nodal DOFs `[x, y, phi]`.
/// An end moment `2 pi EI / L` rolls the beam into a full circle: the tip returns to the root.
pub fn end_moment_static(
    params: &RobotParams,
    elements: usize,
    moment: f64,
    increments: usize,
) -> Result<Vec<[f64; 3]>, FemError> {
    check_elements(elements)?;
    if increments == 0 || !moment.is_finite() {
        return Err(FemError::Input(format!(
            "need increments >= 1 and a finite moment, got {increments}, {moment}"
        )));
    }
    let els = straight_elements(params.l, elements);
    let mut q = straight_dofs(params.l, elements);
    let n = q.len();
    for step in 1..=increments {
        let load = moment * step as f64 / increments as f64;
        let mut converged = false;
        for _ in 0..50 {
            let mut k = DMatrix::zeros(n, n);
            let mut r = DVector::zeros(n);
            for el in &els {
                let st = ElementState::new(el, &element_dofs(&q, el));
                let (f, ke) = st.internal(params.ea(), params.ei());
                scatter(&mut k, el, &ke);
                for j in 0..6 {
                    r[3 * el.nodes[j / 3] + j % 3] -= f[j];
                }
            }
            r[n - 1] += load;
            // clamp node 0
            for d in 0..3 {
                k.row_mut(d).fill(0.0);
                k.column_mut(d).fill(0.0);
                k[(d, d)] = 1.0;
                r[d] = 0.0;
            }
            let dq = k.lu().solve(&r).ok_or(FemError::Newton {
                t: 0.0,
                h: 0.0,
                reason: NewtonFailure::SingularStiffness,
            })?;
            for j in 0..n {
                q[j] += dq[j];
            }
            if dq.amax() < 1e-13 * params.l {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(FemError::Newton {
                t: 0.0,
                h: 0.0,
                reason: NewtonFailure::StaticNoConvergence { step },
            });
        }
    }
    Ok(q.chunks(3).map(|c| [c[0], c[1], c[2]]).collect())
}
