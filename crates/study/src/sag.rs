//! A linear estimate of the star's static sag under gravity, the scale of the derived key
//! `derived.g_share` (`docs/studies.md`, "Derived keys", Eqs. D1-D4): each arm a cantilever
//! clamped at the junction G, held at its sleeve (distance `d` from G) by a force normal to it
//! (the sleeve slides and turns freely, Lp taken as a point), under its weight along its whole
//! length. A scale, not a prediction: on the paper's robot under `g = [0, -9.81]` at the centre
//! pose it gives `|w_2G|` 1.44 mm, the tips of beams 2 and 3 4.16 mm and the sleeves' slope
//! 0.0033 rad, where the AMM and the FEM agree on 1.54 mm, 2.53 mm and 0.0061 rad (the sleeve's
//! length, a straight stretch of the beam, shifts the load between the arm and the overhang).

/// One arm of the star: length [m], bending stiffness [N m^2], mass per length [kg/m], weld angle
/// [rad] (its axis `e = (sin phi, -cos phi)` at theta = 0, `docs/conventions.md`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arm {
    pub l: f64,
    pub ei: f64,
    pub rho: f64,
    pub weld: f64,
}

/// The sag of Eq. D4: per arm the junction's displacement normal to it `w_iG` [m], the tip's
/// `w_i(L)` [m] and the slope at the sleeve `theta_i` [rad], all from the rigid pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sag {
    pub w_g: [f64; 3],
    pub w_tip: [f64; 3],
    pub slope: [f64; 3],
}

/// The sag of the star of `arms` held at its sleeves at distance `d` [m] from G under gravity `g`
/// [m/s^2] (Eqs. D1-D4); `None` when the system is singular (no arm holds).
pub fn star_sag(arms: &[Arm; 3], d: f64, g: [f64; 2]) -> Option<Sag> {
    let n = arms.map(|a| [a.weld.cos(), a.weld.sin()]);
    let q: [f64; 3] = std::array::from_fn(|i| arms[i].rho * (g[0] * n[i][0] + g[1] * n[i][1]));
    // Eq. D1: R_i = -k_i (u . n_i + psi d + c_i)
    let k = arms.map(|a| 3.0 * a.ei / d.powi(3));
    let c: [f64; 3] = std::array::from_fn(|i| {
        let (l, ei) = (arms[i].l, arms[i].ei);
        q[i] * d * d * (6.0 * l * l - 4.0 * l * d + d * d) / (24.0 * ei)
    });
    // Eqs. D2-D3 in (u_x, u_y, psi): A x = b
    let mut a = [[0.0; 3]; 3];
    let mut b = [0.0; 3];
    let weight: f64 = arms.iter().map(|a| a.rho * a.l).sum();
    for i in 0..3 {
        let row = [n[i][0], n[i][1], d];
        for r in 0..2 {
            for (col, v) in row.iter().enumerate() {
                a[r][col] += k[i] * n[i][r] * v;
            }
            b[r] -= k[i] * c[i] * n[i][r];
        }
        for (col, v) in row.iter().enumerate() {
            a[2][col] += k[i] * d * v;
        }
        b[2] += q[i] * arms[i].l * arms[i].l / 2.0 - k[i] * d * c[i];
    }
    b[0] += g[0] * weight;
    b[1] += g[1] * weight;
    let [ux, uy, psi] = solve3(a, b)?;
    let r: [f64; 3] = std::array::from_fn(|i| -k[i] * (ux * n[i][0] + uy * n[i][1] + psi * d + c[i]));
    let w_g: [f64; 3] = std::array::from_fn(|i| ux * n[i][0] + uy * n[i][1]);
    Some(Sag {
        w_g,
        w_tip: std::array::from_fn(|i| {
            let (l, ei) = (arms[i].l, arms[i].ei);
            w_g[i] + psi * l + q[i] * l.powi(4) / (8.0 * ei) + r[i] * d * d * (3.0 * l - d) / (6.0 * ei)
        }),
        slope: std::array::from_fn(|i| {
            let (l, ei) = (arms[i].l, arms[i].ei);
            psi + q[i] * d * (3.0 * l * l - 3.0 * l * d + d * d) / (6.0 * ei) + r[i] * d * d / (2.0 * ei)
        }),
    })
}

/// `A x = b` by Cramer's rule; `None` when `A` is singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&a);
    if !(d.is_finite() && d.abs() > 0.0) {
        return None;
    }
    Some(std::array::from_fn(|j| {
        let mut m = a;
        for (row, v) in m.iter_mut().zip(b) {
            row[j] = v;
        }
        det(&m) / d
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> [Arm; 3] {
        std::array::from_fn(|i| Arm {
            l: 0.5,
            ei: 0.5,
            rho: 0.234,
            weld: (120.0 * i as f64).to_radians(),
        })
    }

    /// Hand statics of the paper's star under g = (0, -9.81): beam 1 hangs along g (no normal
    /// load, no reaction); beams 2 and 3 carry the weight `3 rho L g` by `2 R cos 30 deg`, and
    /// Eq. D1 of beam 2 gives `u` from R (the numbers of the module docs).
    #[test]
    fn the_paper_star_sags_as_its_hand_statics() {
        let s = star_sag(&paper(), 0.18, [0.0, -9.81]).unwrap();
        let r = 3.0 * 0.234 * 0.5 * 9.81 / (2.0 * 30f64.to_radians().cos());
        let q = -0.234 * 9.81 * 30f64.to_radians().cos();
        let d: f64 = 0.18;
        let v_d = r * d.powi(3) / 1.5 + q * d * d * (1.5 - 0.36 + d * d) / 12.0;
        // beam 2's normal n_2 = (cos 120, sin 120): u . n_2 = -u_y sin 120 = -v(d)
        assert!((s.w_g[1] + v_d).abs() < 1e-12, "{s:?} vs {v_d}");
        assert!(s.w_g[0].abs() < 1e-15 && (s.w_g[1] + s.w_g[2]).abs() < 1e-15);
        assert!((s.w_g[1].abs() - 1.436e-3).abs() < 1e-6 && (s.w_tip[1].abs() - 4.158e-3).abs() < 1e-6);
        // linear in g
        let half = star_sag(&paper(), 0.18, [0.0, -4.905]).unwrap();
        assert!((2.0 * half.slope[1] / s.slope[1] - 1.0).abs() < 1e-12);
    }
}
