//! Speed of the FEM on the paper's cases at the paper's mesh (300 elements) and the default step
//! (issue 5: at most 2 s on one core). Case 2 (s = [t^2, -0.5 t^2, -0.5 t^2], 0.4 s) and case 1
//! (s_i = t^2, 0.5 s).

use criterion::{criterion_group, criterion_main, Criterion};
use flexstar_model::{catalogue, FemSettings};

fn bench(c: &mut Criterion) {
    let settings = FemSettings::default();
    let mut g = c.benchmark_group("fem_300_elements");
    g.sample_size(10);
    for (name, k) in [("case2_0.4s", 2), ("case1_0.5s", 1)] {
        let exp = catalogue::paper_case(k);
        g.bench_function(name, |b| b.iter(|| flexstar_fem::solve(&exp, &settings, None).unwrap()));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
