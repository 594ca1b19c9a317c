//! Further starts of the search (`docs/measured.md` 4.6): points of the scaled box spread by
//! Halton's low-discrepancy sequence, so that a few of them cover the box evenly in every
//! dimension, whatever the number of parameters.

/// The first primes: Halton's bases, one per parameter (more parameters reuse them scrambled by
/// the point's index, which no fit of this size needs).
const BASES: [u32; 12] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37];

/// The margin kept from the box's faces: a start on a bound would begin with that parameter
/// held (Eq. LS7).
const MARGIN: f64 = 0.05;

/// Element `index` (from 1) of the van der Corput sequence in `base`: the digits of `index`
/// mirrored about the radix point, in [0, 1).
fn radical_inverse(mut index: u64, base: u32) -> f64 {
    let b = f64::from(base);
    let (mut value, mut scale) = (0.0, 1.0 / b);
    while index > 0 {
        value += (index % u64::from(base)) as f64 * scale;
        index /= u64::from(base);
        scale /= b;
    }
    value
}

/// `count` starts for `p` parameters in scaled coordinates (Eq. LS5), each coordinate in
/// `[MARGIN, 1 - MARGIN]`: Halton points 1..=count.
pub fn halton_starts(p: usize, count: usize) -> Vec<Vec<f64>> {
    (1..=count as u64)
        .map(|i| {
            (0..p)
                .map(|k| {
                    let h = radical_inverse(i + (k / BASES.len()) as u64 * 7, BASES[k % BASES.len()]);
                    MARGIN + (1.0 - 2.0 * MARGIN) * h
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Van der Corput in base 2: 1/2, 1/4, 3/4, 1/8, 5/8 (the textbook sequence).
    #[test]
    fn base_two_mirrors_the_binary_digits() {
        let got: Vec<f64> = (1..=5).map(|i| radical_inverse(i, 2)).collect();
        assert_eq!(got, vec![0.5, 0.25, 0.75, 0.125, 0.625]);
    }

    /// Eight starts in two dimensions put one point in each half of every axis at least twice,
    /// and stay off the faces.
    #[test]
    fn starts_cover_the_box_off_its_faces() {
        let s = halton_starts(2, 8);
        for k in 0..2 {
            let low = s.iter().filter(|u| u[k] < 0.5).count();
            assert!((3..=5).contains(&low), "axis {k}: {low} of 8 below the middle");
        }
        assert!(s.iter().flatten().all(|&u| (MARGIN..=1.0 - MARGIN).contains(&u)));
    }
}
