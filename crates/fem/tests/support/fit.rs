//! A least-squares fit the FEM's static tests read a deflected overhang with.

/// Value and slope at `x0` of the least-squares quartic through the nodes `(x, w)` beyond `x0`
/// (the cantilever's exact shape in linear theory, which the Hermite elements reproduce at the
/// nodes).
pub fn quartic_at(x: &[f64], w: &[f64], x0: f64) -> (f64, f64) {
    let pts: Vec<(f64, f64)> = x
        .iter()
        .zip(w)
        .filter(|(xk, _)| **xk > x0)
        .map(|(a, b)| (a - x0, *b))
        .collect();
    assert!(pts.len() >= 8, "too few nodes on the overhang");
    let scale = pts.last().unwrap().0;
    let mut ata = [[0.0; 5]; 5];
    let mut atb = [0.0; 5];
    for &(xk, wk) in &pts {
        let basis: [f64; 5] = std::array::from_fn(|j| (xk / scale).powi(j as i32));
        for r in 0..5 {
            atb[r] += basis[r] * wk;
            for c in 0..5 {
                ata[r][c] += basis[r] * basis[c];
            }
        }
    }
    let c = nalgebra::Matrix5::from_fn(|r, k| ata[r][k])
        .lu()
        .solve(&nalgebra::Vector5::from_fn(|r, _| atb[r]))
        .expect("the normal equations of the fit are regular");
    (c[0], c[1] / scale)
}
