//! Gauss-Legendre quadrature on [-1, 1] (Abramowitz & Stegun, table 25.4).

/// Points and weights of the n-point Gauss-Legendre rule, n in 1..=5.
pub fn gauss_legendre(n: usize) -> (&'static [f64], &'static [f64]) {
    const P1: [f64; 1] = [0.0];
    const W1: [f64; 1] = [2.0];
    const P2: [f64; 2] = [-0.577_350_269_189_625_8, 0.577_350_269_189_625_8];
    const W2: [f64; 2] = [1.0, 1.0];
    const P3: [f64; 3] = [-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4];
    const W3: [f64; 3] = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    const P4: [f64; 4] = [
        -0.861_136_311_594_052_6,
        -0.339_981_043_584_856_3,
        0.339_981_043_584_856_3,
        0.861_136_311_594_052_6,
    ];
    const W4: [f64; 4] = [
        0.347_854_845_137_453_9,
        0.652_145_154_862_546_1,
        0.652_145_154_862_546_1,
        0.347_854_845_137_453_9,
    ];
    const P5: [f64; 5] = [
        -0.906_179_845_938_664,
        -0.538_469_310_105_683_1,
        0.0,
        0.538_469_310_105_683_1,
        0.906_179_845_938_664,
    ];
    const W5: [f64; 5] = [
        0.236_926_885_056_189_1,
        0.478_628_670_499_366_5,
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
    ];
    match n {
        1 => (&P1, &W1),
        2 => (&P2, &W2),
        3 => (&P3, &W3),
        4 => (&P4, &W4),
        5 => (&P5, &W5),
        _ => panic!("gauss_legendre: n = {n} not in 1..=5"),
    }
}

/// Points and weights of the n-point Gauss-Legendre rule on [-1, 1] for any n >= 1, by Newton's
/// method on the Legendre recurrence from the Tricomi-type guess `cos(pi (i + 3/4) / (n + 1/2))`.
/// Exact for polynomials of degree 2n - 1 (tested against the tabulated rules and monomials).
pub fn gauss_legendre_rule(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut w) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..n {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() <= 1e-16 {
                break;
            }
        }
        // ascending order, like the tables
        x[n - 1 - i] = z;
        w[n - 1 - i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

/// Integral of f over [a, b] with the n-point rule.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let (p, w) = gauss_legendre(n);
    let (c, r) = (0.5 * (a + b), 0.5 * (b - a));
    p.iter().zip(w).map(|(x, wi)| wi * f(c + r * x)).sum::<f64>() * r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_for_polynomials_of_degree_2n_minus_1() {
        for n in 1..=5 {
            let deg = 2 * n - 1;
            let got = integrate(|x| x.powi(deg as i32) + 1.0, 0.0, 2.0, n);
            let exact = 2f64.powi(deg as i32 + 1) / (deg as f64 + 1.0) + 2.0;
            assert!((got - exact).abs() < 1e-12 * exact, "n = {n}");
        }
    }

    #[test]
    fn generated_rules_match_the_tables_and_are_exact_to_degree_2n_minus_1() {
        for n in 1..=5 {
            let (p, w) = gauss_legendre(n);
            let (x, v) = gauss_legendre_rule(n);
            for k in 0..n {
                assert!(
                    (p[k] - x[k]).abs() < 1e-15 && (w[k] - v[k]).abs() < 1e-15,
                    "n = {n}, k = {k}"
                );
            }
        }
        // A&S table 25.4, n = 10: largest node and its weight (15 digits)
        let (x, w) = gauss_legendre_rule(10);
        assert!((x[9] - 0.973_906_528_517_172).abs() < 1e-15 && (w[9] - 0.066_671_344_308_688).abs() < 1e-15);
        for n in [10, 20] {
            let (x, w) = gauss_legendre_rule(n);
            for deg in 0..2 * n {
                let got: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = if deg % 2 == 1 { 0.0 } else { 2.0 / (deg as f64 + 1.0) };
                assert!((got - exact).abs() < 2e-15, "n = {n}, degree {deg}: {got} vs {exact}");
            }
        }
    }
}
