//! Speed of the FEM on the paper's cases at the paper's mesh (300 elements) and the default step
//! (issue 5: at most 2 s on one core). Case 2 (s = [t^2, -0.5 t^2, -0.5 t^2], 0.4 s) and case 1
//! (s_i = t^2, 0.5 s).

use criterion::{criterion_group, criterion_main, Criterion};
use flexstar_model::{Experiment, FemSettings, TimeSpan, Trajectory};

fn case(k: [f64; 3], t_end: f64) -> Experiment {
    Experiment {
        name: "bench".into(),
        description: String::new(),
        robot: Default::default(),
        time: TimeSpan { t_end, dt_out: 1e-3 },
        trajectory: Trajectory::quadratic(k),
        amm: Default::default(),
        fem: Default::default(),
        source: Default::default(),
    }
}

fn bench(c: &mut Criterion) {
    let settings = FemSettings::default();
    let mut g = c.benchmark_group("fem_300_elements");
    g.sample_size(10);
    for (name, k, t_end) in [
        ("case2_0.4s", [1.0, -0.5, -0.5], 0.4),
        ("case1_0.5s", [1.0, 1.0, 1.0], 0.5),
    ] {
        let exp = case(k, t_end);
        g.bench_function(name, |b| b.iter(|| flexstar_fem::solve(&exp, &settings, None).unwrap()));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
