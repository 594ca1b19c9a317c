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
}
