//! The static shapes of unit slider displacements (`docs/modes.md`, stuck sleeves, Eq. S4): on
//! a sliders-free pose system, the coordinates `R_j` [m per m of slider j] that minimise the
//! strain energy `q^T K q / 2` under the constraint rows (`C q = 0`) with slider j displaced by one
//! and the others held (`S q = e_j`). On a sliding system this is the rigid motion the sliders
//! impose (zero energy); on a stuck one it strains the star (component-mode synthesis' constraint
//! modes). Solved on the null space of `[C; S]` (redundant constraint rows allowed): a particular
//! solution from the pseudo-inverse, then the energy minimised over the null space (its projector
//! from the singular vectors).

use flexstar_amm::pose_modes::PoseSystem;
use nalgebra::{DMatrix, DVector};

use crate::ModalError;

/// Relative size below which a singular value of `[C; S]` counts as zero.
const RANK_TOL: f64 = 1e-10;

/// `R` as rows: `r[a][j]` = coordinate a of the static shape of slider j (`n` rows).
pub(crate) fn static_shapes(sys: &PoseSystem) -> Result<Vec<[f64; 3]>, ModalError> {
    let n = sys.n;
    let sliders = [0, 1, 2].map(|i| sys.slider_index(i));
    let [Some(s1), Some(s2), Some(s3)] = sliders else {
        return Err(ModalError::Input(
            "the static shapes of the sliders need the sliders-free system".into(),
        ));
    };
    let si = [s1, s2, s3];
    let rows = sys.rows + 3;
    let a = DMatrix::from_fn(rows, n, |r, c| {
        if r < sys.rows {
            sys.c[r * n + c]
        } else {
            f64::from(u8::from(c == si[r - sys.rows]))
        }
    });
    // the rank of [C; S] from its singular values; P the projector on its null space
    let svd = a.clone().svd(true, true);
    let eps = RANK_TOL * svd.singular_values.max();
    let v_t = svd
        .v_t
        .as_ref()
        .ok_or_else(|| singular("no singular vectors of the constraint rows"))?;
    let mut p = DMatrix::<f64>::identity(n, n);
    for (r, sigma) in svd.singular_values.iter().enumerate() {
        if *sigma > eps {
            let v = v_t.row(r).transpose();
            p -= &v * v.transpose();
        }
    }
    // the energy over q_p + P z: (P K P + I - P) z = -P K q_p, whose solution has (I - P) z = 0
    let k = DMatrix::from_row_slice(n, n, &sys.k);
    let pk = &p * &k;
    let lu = (&pk * &p + DMatrix::<f64>::identity(n, n) - &p).lu();
    let mut out = vec![[0.0; 3]; n];
    for j in 0..3 {
        let mut b = DVector::zeros(rows);
        b[sys.rows + j] = 1.0;
        let particular = svd
            .solve(&b, eps)
            .map_err(|e| ModalError::Infeasible(format!("the sliders' static shapes: {e}")))?;
        let z = lu
            .solve(&(-(&pk * &particular)))
            .ok_or_else(|| singular("the strain energy on the constrained motions is singular"))?;
        let r = particular + &p * z;
        let residual = (&a * &r - &b).amax();
        // a NaN residual fails too
        if residual.is_nan() || residual > 1e-8 {
            return Err(singular(&format!(
                "slider {} cannot be displaced alone with the constraints held (residual {residual:e})",
                j + 1
            )));
        }
        for (row, v) in out.iter_mut().zip(r.iter()) {
            row[j] = *v;
        }
    }
    Ok(out)
}

fn singular(why: &str) -> ModalError {
    ModalError::Infeasible(format!("the sliders' static shapes at this pose: {why}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexstar_model::{Experiment, Sleeves, Sliders};

    /// On the sliding system Eq. S4's minimiser is the rigid motion the sliders impose: its strain
    /// energy is nil to round-off, it is what the sliding system's rigid modes give (beam part
    /// times the inverse of the slider part: a second characterisation, through the eigensolver)
    /// to their own accuracy, and its slider rows are the identity; at a turned off-centre pose.
    #[test]
    fn on_sliding_sleeves_the_static_shapes_are_the_rigid_motion() {
        let toml = "name = \"t\"\n[time]\nt_end = 0.5\ndt_out = 0.001\n[trajectory]\nkind = \"polynomial\"\n\
                    s1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n";
        let exp = Experiment::from_toml_str(toml, std::path::Path::new("t.toml")).unwrap();
        let robot = crate::robot(&exp).unwrap();
        let pose = crate::pose::pose_from_task(&robot, 0.03, -0.02, 0.1).unwrap();
        let model = crate::analysis::amm_pose_model(&exp)
            .unwrap()
            .with_sleeves(Sleeves::Sliding);
        let sys = model.system_at(&pose, Sliders::Free);
        let shapes = static_shapes(&sys).unwrap();
        let free = model.modes_at(&pose, Sliders::Free, 1).unwrap();
        assert_eq!(free.rigid, 3);
        let rigid = &free.shapes[..3];
        let s = nalgebra::Matrix3::from_fn(|i, k| rigid[k][sys.slider_index(i).unwrap()]);
        let s_inv = s.try_inverse().unwrap();
        let scale = shapes.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut worst = 0.0f64;
        for (a, row) in shapes.iter().enumerate() {
            for j in 0..3 {
                let from_modes: f64 = (0..3).map(|k| rigid[k][a] * s_inv[(k, j)]).sum();
                worst = worst.max((row[j] - from_modes).abs());
            }
        }
        // the rigid motion's strain energy is nil: the static shapes' is, to round-off of K
        let n = sys.n;
        let kmax = sys.k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let energy = |r: &dyn Fn(usize) -> f64| -> f64 {
            (0..n)
                .map(|a| (0..n).map(|b| r(a) * sys.k[a * n + b] * r(b)).sum::<f64>())
                .sum()
        };
        for j in 0..3 {
            let e_shapes = energy(&|a| shapes[a][j]);
            let e_modes = energy(&|a| (0..3).map(|k| rigid[k][a] * s_inv[(k, j)]).sum::<f64>());
            eprintln!(
                "slider {}: strain energy of the static shape {e_shapes:e}, of the rigid modes' {e_modes:e}",
                j + 1
            );
            assert!(e_shapes.abs() <= 1e-14 * kmax * scale * scale, "{e_shapes:e}");
        }
        // the eigensolver's rigid modes are accurate to about 1e-7 here (their strain energy is
        // 1e-13, not nil): agreement to 1e-6 of the largest entry
        eprintln!("static shapes against the rigid modes: {worst:e} (largest entry {scale:e})");
        assert!(worst <= 1e-6 * scale, "{worst:e} of {scale:e}");
        for i in 0..3 {
            let row = &shapes[sys.slider_index(i).unwrap()];
            for (j, v) in row.iter().enumerate() {
                let expected = f64::from(u8::from(i == j));
                assert!((v - expected).abs() < 1e-12, "slider {i}, shape {j}: {v}");
            }
        }
    }
}
