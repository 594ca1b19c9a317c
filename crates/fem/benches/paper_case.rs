//! Speed of the FEM on the paper's cases at the default step (issue 13: one paper case at the
//! paper's mesh, 300 elements, in at most 0.15 s on one core; 3000 elements in at most 10 times
//! the 300-element time). Case 2 (s = [t^2, -0.5 t^2, -0.5 t^2], 0.4 s) at 300 and 3000 elements,
//! and case 1 (s_i = t^2, 0.5 s) at 300. Run pinned to one core:
//! `taskset -c 1 cargo bench -p flexstar-fem --bench paper_case`.

use criterion::{criterion_group, criterion_main, Criterion};
use flexstar_model::{catalogue, FemSettings};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("fem");
    g.sample_size(10);
    for (name, k, elements) in [
        ("case2_0.4s_300el", 2, 300),
        ("case1_0.5s_300el", 1, 300),
        ("case2_0.4s_3000el", 2, 3000),
    ] {
        let exp = catalogue::paper_case(k);
        let settings = FemSettings {
            elements,
            ..FemSettings::default()
        };
        g.bench_function(name, |b| b.iter(|| flexstar_fem::solve(&exp, &settings, None).unwrap()));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
