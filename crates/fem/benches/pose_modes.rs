//! Speed of the FEM's modes at one pose (`docs/modes.md`: at most 50 ms at 300 elements): the paper's
//! robot at an off-centre pose, the first six modes, sliders locked and free, by the sparse
//! subspace iteration (`pose_modes`, assembly included) and, for comparison, the dense null-space
//! path (`pose_modes_dense`). Run pinned to one core:
//! `taskset -c 1 cargo bench -p flexstar-fem --features bench --bench pose_modes`.

use criterion::{criterion_group, criterion_main, Criterion};
use flexstar_fem::pose_modes::{pose_modes, pose_modes_dense};
use flexstar_model::{RestPose, RobotParams, Sliders};

fn bench(c: &mut Criterion) {
    let p = RobotParams::paper();
    let pose = RestPose {
        s: [0.0; 3],
        g: [0.0; 2],
        theta: 0.0,
        xp: [0.16, 0.21, 0.18],
    };
    let mut g = c.benchmark_group("fem_pose_modes");
    g.sample_size(10);
    for sliders in [Sliders::Locked, Sliders::Free] {
        g.bench_function(format!("sparse_300el_6modes_{}", sliders.name()), |b| {
            b.iter(|| pose_modes(&p, &pose, sliders, 300, 6).unwrap())
        });
    }
    g.bench_function("dense_300el_6modes_locked", |b| {
        b.iter(|| pose_modes_dense(&p, &pose, Sliders::Locked, 300, 6).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
