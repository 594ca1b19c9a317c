//! Mode families (Eq. 34-1) against outside references: textbook roots beta*L (Blevins, "Formulas
//! for natural frequency and mode shape", table 8-1; the slide-free roots are the roots of
//! tan(bL) = -tanh(bL)), their exponentially small distance to the asymptotes, orthonormality and
//! stiffness orthogonality by an independent quadrature (Clenshaw-Curtis, not the crate's
//! Gauss-Legendre), the closed-form integrals
//! Phi_j and Psi_j, and the frequency formula.

use flexstar_amm::{parse_family, AmmError, ModeSet};
use flexstar_model::{ModeFamily, RobotParams};
use std::f64::consts::PI;

const ALL: [ModeFamily; 4] = [
    ModeFamily::PinnedFree,
    ModeFamily::SlideFree,
    ModeFamily::FreeFree,
    ModeFamily::ClampedFree,
];

/// Points per panel of the composite rule, minus one (even).
const CC_ORDER: usize = 20;

/// Nodes and weights of the (n + 1)-point Clenshaw-Curtis rule on [-1, 1], n even: the nodes
/// `cos(k pi / n)`, the weights those of integrating the interpolating Chebyshev series term by
/// term (Clenshaw & Curtis 1960; Trefethen, "Spectral Methods in MATLAB", 2000, chapter 12).
/// Exact for polynomials of degree n. A different rule from the crate's Gauss-Legendre
/// (`flexstar_numerics::quadrature`), so that the checks below do not share its errors.
fn clenshaw_curtis(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 2 && n.is_multiple_of(2));
    let nf = n as f64;
    let end = 1.0 / (nf * nf - 1.0);
    (0..=n)
        .map(|k| {
            let theta = PI * k as f64 / nf;
            if k == 0 || k == n {
                return (theta.cos(), end);
            }
            let series: f64 = (1..n / 2)
                .map(|j| 2.0 * (2.0 * j as f64 * theta).cos() / (4.0 * (j * j) as f64 - 1.0))
                .sum();
            (theta.cos(), 2.0 / nf * (1.0 - series - (nf * theta).cos() * end))
        })
        .unzip()
}

/// Composite Clenshaw-Curtis rule on [0, L] with panels no wider than one radian of the highest
/// mode.
fn nodes(l: f64, beta_max: f64) -> Vec<(f64, f64)> {
    let (x, w) = clenshaw_curtis(CC_ORDER);
    let panels = ((beta_max * l).ceil() as usize).max(4);
    let h = l / panels as f64;
    (0..panels)
        .flat_map(|p| {
            let c = (p as f64 + 0.5) * h;
            x.iter()
                .zip(&w)
                .map(move |(xi, wi)| (c + 0.5 * h * xi, 0.5 * h * wi))
                .collect::<Vec<_>>()
        })
        .collect()
}

#[test]
fn clenshaw_curtis_is_exact_to_degree_n_and_matches_closed_forms() {
    let (x, w) = clenshaw_curtis(CC_ORDER);
    for deg in 0..=CC_ORDER {
        let got: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
        let exact = if deg % 2 == 1 { 0.0 } else { 2.0 / (deg as f64 + 1.0) };
        assert!((got - exact).abs() < 1e-14, "degree {deg}: {got} vs {exact}");
    }
    // the composite rule on oscillating and growing integrands (beta = 20 over [0, 0.5])
    let q = nodes(0.5, 20.0);
    let cos: f64 = q.iter().map(|(x, w)| w * (40.0 * x).cos()).sum();
    assert!((cos - 20f64.sin() / 40.0).abs() < 1e-14, "{cos}");
    let cosh: f64 = q.iter().map(|(x, w)| w * (20.0 * x).cosh()).sum();
    assert!((cosh / (10f64.sinh() / 20.0) - 1.0).abs() < 1e-13, "{cosh}");
}

#[test]
fn textbook_roots_to_six_digits() {
    // Blevins table 8-1 (clamped-free, pinned-free, free-free); slide-free: tan b + tanh b = 0
    let table = [
        (ModeFamily::PinnedFree, 1, [3.926602, 7.068583, 10.210176]),
        (ModeFamily::SlideFree, 1, [2.365020, 5.497804, 8.639380]),
        (ModeFamily::FreeFree, 2, [4.730041, 7.853205, 10.995608]),
        (ModeFamily::ClampedFree, 0, [1.875104, 4.694091, 7.854757]),
    ];
    let p = RobotParams::paper();
    for (fam, rigid, roots) in table {
        let ms = ModeSet::new(fam, rigid + 3, &p).unwrap();
        assert_eq!(ms.rigid_count(), rigid, "{fam}");
        let bl = ms.beta_l();
        assert!(
            bl[..rigid].iter().chain(&ms.lambda()[..rigid]).all(|v| *v == 0.0),
            "{fam}: rigid modes"
        );
        for (k, want) in roots.iter().enumerate() {
            assert!(
                (bl[rigid + k] - want).abs() < 5e-7,
                "{fam} root {}: {} vs {want}",
                k + 1,
                bl[rigid + k]
            );
        }
    }
}

#[test]
fn roots_approach_asymptotes_exponentially() {
    // First-order corrections from the characteristic equations (b_n = a_n + eps_n):
    // clamped-free cos b = -sech b: eps = (-1)^(n+1) 2 e^-a, a = (2n-1) pi/2
    // free-free    cos b =  sech b: eps = (-1)^(n+1) 2 e^-a, a = (2n+1) pi/2
    // pinned-free  tan b =  tanh b: eps = -e^-2a,            a = (4n+1) pi/4
    // slide-free   tan b = -tanh b: eps = +e^-2a,            a = (4n-1) pi/4
    let p = RobotParams::paper();
    for fam in ALL {
        let ms = ModeSet::new(fam, 400, &p).unwrap();
        let r = ms.rigid_count();
        let bl = ms.beta_l();
        for n in 1..=(400 - r) {
            let sgn = if n % 2 == 1 { 1.0 } else { -1.0 };
            let nf = n as f64;
            let (a, eps) = match fam {
                ModeFamily::ClampedFree => (
                    (2.0 * nf - 1.0) * PI / 2.0,
                    sgn * 2.0 * (-(2.0 * nf - 1.0) * PI / 2.0).exp(),
                ),
                ModeFamily::FreeFree => (
                    (2.0 * nf + 1.0) * PI / 2.0,
                    sgn * 2.0 * (-(2.0 * nf + 1.0) * PI / 2.0).exp(),
                ),
                ModeFamily::PinnedFree => ((4.0 * nf + 1.0) * PI / 4.0, -(-(4.0 * nf + 1.0) * PI / 2.0).exp()),
                ModeFamily::SlideFree => ((4.0 * nf - 1.0) * PI / 4.0, (-(4.0 * nf - 1.0) * PI / 2.0).exp()),
                ModeFamily::Enriched => unreachable!("not an analytic family"),
            };
            let got = bl[r + n - 1] - a;
            if n >= 3 && eps.abs() > 1e-10 {
                // the next correction is O(eps^2 a): relative agreement better than 1 %
                assert!((got - eps).abs() < 1e-2 * eps.abs(), "{fam} n={n}: {got:e} vs {eps:e}");
            } else if eps.abs() < 1e-15 * a {
                assert!(
                    got.abs() <= 4.0 * f64::EPSILON * a,
                    "{fam} n={n}: {got:e} off the asymptote"
                );
            }
        }
    }
}

#[test]
fn orthonormal_and_stiffness_orthogonal_at_n_100() {
    // int phi_j phi_m = delta_jm and (EI/rho) int phi_j'' phi_m'' = lambda_m delta_jm, residual < 1e-9
    let p = RobotParams::paper();
    for fam in ALL {
        let n = 100;
        let ms = ModeSet::new(fam, n, &p).unwrap();
        let bmax = ms.beta_l()[n - 1] / p.l;
        let q = nodes(p.l, bmax);
        let tab: Vec<Vec<[f64; 4]>> = (0..n)
            .map(|m| q.iter().map(|(x, _)| ms.eval(m, *x)).collect())
            .collect();
        let lam = ms.lambda();
        let (mut worst_m, mut worst_k) = (0.0f64, 0.0f64);
        for j in 0..n {
            for m in j..n {
                let (mut mass, mut stiff) = (0.0, 0.0);
                for (k, (_, w)) in q.iter().enumerate() {
                    mass += w * tab[j][k][0] * tab[m][k][0];
                    stiff += w * tab[j][k][2] * tab[m][k][2];
                }
                stiff *= ms.ei_over_rho();
                let want = if j == m { 1.0 } else { 0.0 };
                worst_m = worst_m.max((mass - want).abs());
                // relative to the larger eigenvalue of the pair (rigid pairs: absolute, scale 1)
                let scale = lam[j].max(lam[m]).max(1.0);
                let want_k = if j == m { lam[m] } else { 0.0 };
                worst_k = worst_k.max((stiff - want_k).abs() / scale);
            }
        }
        eprintln!("{fam}: N = 100 orthonormality residual {worst_m:.2e}, stiffness {worst_k:.2e}");
        assert!(worst_m < 1e-9, "{fam}: orthonormality residual {worst_m:e}");
        assert!(worst_k < 1e-9, "{fam}: stiffness orthogonality residual {worst_k:e}");
    }
}

#[test]
fn integrals_phi_and_psi_match_quadrature() {
    // Eqs. 37, 44: Phi_j = int phi_j, Psi_j = int x phi_j (closed forms from the ODE) vs quadrature
    let p = RobotParams::paper();
    for fam in ALL {
        let n = 60;
        let ms = ModeSet::new(fam, n, &p).unwrap();
        let q = nodes(p.l, ms.beta_l()[n - 1] / p.l);
        for m in 0..n {
            let phi: f64 = q.iter().map(|(x, w)| w * ms.eval(m, *x)[0]).sum();
            let psi: f64 = q.iter().map(|(x, w)| w * x * ms.eval(m, *x)[0]).sum();
            assert!(
                (phi - ms.phi_integral()[m]).abs() < 1e-12,
                "{fam} m={m}: Phi {phi} vs {}",
                ms.phi_integral()[m]
            );
            assert!(
                (psi - ms.x_phi_integral()[m]).abs() < 1e-12,
                "{fam} m={m}: Psi {psi} vs {}",
                ms.x_phi_integral()[m]
            );
        }
    }
}

#[test]
fn mode_derivatives_match_finite_differences() {
    // phi', phi'', phi''' against 4th-order central differences of the next lower derivative
    let p = RobotParams::paper();
    let ms = ModeSet::new(ModeFamily::FreeFree, 30, &p).unwrap();
    let h = 1e-5;
    for m in [0, 1, 2, 10, 29] {
        for x in [0.05, 0.2, 0.37, 0.45] {
            let e = |x: f64| ms.eval(m, x);
            for k in 0..3 {
                let fd = (-e(x + 2.0 * h)[k] + 8.0 * e(x + h)[k] - 8.0 * e(x - h)[k] + e(x - 2.0 * h)[k]) / (12.0 * h);
                let exact = e(x)[k + 1];
                let scale = (ms.beta_l()[m] / p.l).max(1.0).powi(k as i32 + 1) / p.l.sqrt();
                assert!((fd - exact).abs() < 1e-7 * scale, "m={m} x={x} k={k}: {fd} vs {exact}");
            }
        }
    }
}

#[test]
fn frequencies_follow_beta_l() {
    // f = (beta L)^2 / (2 pi L^2) sqrt(EI/rho); paper robot, first pinned-free elastic mode 14.348 Hz
    let p = RobotParams::paper();
    let ms = ModeSet::new(ModeFamily::PinnedFree, 4, &p).unwrap();
    let f = ms.frequencies_hz();
    assert_eq!(f[0], 0.0);
    let want = 3.926_602_312_047_919f64.powi(2) / (2.0 * PI * p.l * p.l) * (p.ei() / p.rho).sqrt();
    assert!(
        (f[1] - want).abs() < 1e-9 * want && (f[1] - 14.348).abs() < 1e-3,
        "{}",
        f[1]
    );
}

#[test]
fn bad_mode_counts_and_families_are_rejected() {
    let p = RobotParams::paper();
    for n in [0, 401, 100_000] {
        match ModeSet::new(ModeFamily::FreeFree, n, &p) {
            Err(AmmError::InvalidSetting { key, .. }) => assert_eq!(key, "amm.modes"),
            other => panic!("N = {n}: {other:?}"),
        }
    }
    let err = parse_family("hinged-free").unwrap_err();
    assert!(
        matches!(err, AmmError::UnknownFamily(_)) && err.to_string().contains("hinged-free"),
        "{err}"
    );
    assert_eq!(parse_family("slide-free").unwrap(), ModeFamily::SlideFree);
}
