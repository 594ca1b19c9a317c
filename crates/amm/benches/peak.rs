//! The machine's rate on the kinds of work one AMM step does, at the step's sizes
//! (`docs/amm.md` 2.1, "Cost of a step"): the accurate model at N = 53 has vectors of 53 modes,
//! an 18 x 18 Schur complement (21 x 21 with friction), 4 x 4 sleeve blocks and a 6 x 6
//! junction block, and the geometric stiffness `[G1; G2]` (36 x 18) times three beams. Each
//! kernel's flop count is written beside it; criterion's time per iteration gives the rate.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{DMatrix, DVector, Matrix4, Matrix6, SMatrix};
use std::hint::black_box;

/// A deterministic vector of `n` entries in [-0.5, 0.5).
fn values(n: usize, seed: u64) -> Vec<f64> {
    let mut state = seed;
    (0..n)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        })
        .collect()
}

/// A diagonally dominant m x m matrix (column-major as nalgebra stores it).
fn dominant(m: usize, seed: u64) -> DMatrix<f64> {
    DMatrix::from_vec(m, m, values(m * m, seed)) + DMatrix::identity(m, m) * (m as f64)
}

/// Vector kernels of length 53: the dot product (106 flops), one vector against seven (742),
/// an elementwise scaling (53) and an axpy (106).
fn vectors(c: &mut Criterion) {
    let mut group = c.benchmark_group("peak_vectors_n53");
    let (a, b) = (values(53, 1), values(53, 2));
    let seven: Vec<Vec<f64>> = (0..7).map(|k| values(53, 10 + k)).collect();
    group.bench_function("dot_106flop", |bch| {
        bch.iter(|| flexstar_numerics::vector::dot(black_box(&a), black_box(&b)))
    });
    group.bench_function("dots7_742flop", |bch| {
        let refs: [&[f64]; 7] = std::array::from_fn(|k| &seven[k][..]);
        bch.iter(|| flexstar_numerics::vector::dots(black_box(&a), black_box(refs)))
    });
    let mut out = vec![0.0; 53];
    group.bench_function("scale_53flop", |bch| {
        bch.iter(|| {
            for ((o, x), d) in out.iter_mut().zip(black_box(&a)).zip(black_box(&b)) {
                *o = x * d;
            }
            black_box(&out);
        })
    });
    group.bench_function("axpy_106flop", |bch| {
        bch.iter(|| {
            let c = black_box(0.7);
            for (o, x) in out.iter_mut().zip(black_box(&a)) {
                *o += c * x;
            }
            black_box(&out);
        })
    });
    group.finish();
}

/// Dense kernels of the constraint solve: an 18 x 18 matrix-vector product (648 flops), the
/// dense LU with partial pivoting of 18 x 18 and 21 x 21 (2 m^3 / 3: 3888 and 6174 flops) and
/// its solve (2 m^2: 648), nalgebra's 4 x 4 inverse (about 200 flops), the 6 x 6 LU (144), and
/// faer's product `[G1; G2] alpha` (36 x 18 times 18 x 3: 3888 flops).
fn dense(c: &mut Criterion) {
    let mut group = c.benchmark_group("peak_dense");
    let a18 = dominant(18, 3);
    let x18 = DVector::from_vec(values(18, 4));
    group.bench_function("matvec18_648flop", |bch| bch.iter(|| black_box(&a18) * black_box(&x18)));
    for (m, flops) in [(18, 3888), (21, 6174)] {
        let a = dominant(m, 5);
        group.bench_function(format!("lu{m}_{flops}flop"), |bch| {
            bch.iter(|| black_box(a.clone()).lu())
        });
    }
    let lu = a18.clone().lu();
    group.bench_function("lu18_solve_648flop", |bch| {
        bch.iter(|| {
            let mut b = black_box(x18.clone());
            lu.solve_mut(&mut b);
            b
        })
    });
    let a4 = Matrix4::from_iterator(values(16, 6)) + Matrix4::identity() * 4.0;
    group.bench_function("inverse4_about200flop", |bch| bch.iter(|| black_box(a4).try_inverse()));
    let a6 = Matrix6::from_iterator(values(36, 7)) + Matrix6::identity() * 6.0;
    group.bench_function("lu6_144flop", |bch| bch.iter(|| black_box(a6).lu()));
    let g = faer::Mat::from_fn(36, 18, |r, c| ((r * 18 + c) as f64).sin());
    let alpha = faer::Mat::from_fn(18, 3, |r, c| ((r + 31 * c) as f64).cos());
    let mut prod = faer::Mat::<f64>::zeros(36, 3);
    group.bench_function("faer_gemm36x18x3_3888flop", |bch| {
        bch.iter(|| {
            faer::linalg::matmul::matmul(
                prod.as_mut(),
                faer::Accum::Replace,
                black_box(g.as_ref()),
                black_box(alpha.as_ref()),
                1.0,
                faer::Par::Seq,
            );
            black_box(&prod);
        })
    });
    let s18 = SMatrix::<f64, 18, 18>::from_iterator(values(324, 8));
    let v18 = SMatrix::<f64, 18, 1>::from_iterator(values(18, 9));
    group.bench_function("matvec18_fixed_648flop", |bch| {
        bch.iter(|| black_box(&s18) * black_box(&v18))
    });
    group.finish();
}

criterion_group!(benches, vectors, dense);
criterion_main!(benches);
