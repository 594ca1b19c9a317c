//! Speed of the modal analyses (`docs/modes.md`, "Speed"), the paper's robot with the enriched family at
//! N = 60 modes per beam (the modal default):
//! - AMM modes at one pose, target at most 5 ms: the per-pose cost of a map (mode set built
//!   once: `PoseModel::frequencies_at`, values only, and `PoseModel::modes_at`, with the
//!   shapes) and from scratch (`pose_modes`, the mode set built too);
//! - a 21 x 21 AMM frequency map over Gx, Gy in [-0.15, 0.15] m (415 feasible poses), target at
//!   most 2 s on the 2-core machine (rayon over every core).

use criterion::{criterion_group, criterion_main, Criterion};
use flexstar_amm::pose_modes::{pose_modes, PoseModel, DEFAULT_MODAL_MODES};
use flexstar_modal::freqmap::{freqmap, Axis, Grid, Solver};
use flexstar_modal::pose::pose_from_task;
use flexstar_model::{Experiment, ModeFamily, Sliders};

fn paper_robot() -> Experiment {
    let text = "name = \"bench\"\n[time]\nt_end = 0.5\n[trajectory]\nkind = \"polynomial\"\ns1 = [0.0]\ns2 = [0.0]\ns3 = [0.0]\n";
    Experiment::from_toml_str(text, std::path::Path::new("bench.toml")).expect("valid experiment")
}

fn one_pose(c: &mut Criterion) {
    let exp = paper_robot();
    let pose = pose_from_task(&flexstar_modal::robot(&exp).unwrap(), 0.03, -0.02, 0.1).expect("feasible pose");
    let model = PoseModel::new(&exp.robot, ModeFamily::Enriched, DEFAULT_MODAL_MODES).expect("mode set");
    let mut group = c.benchmark_group("amm_modes_one_pose");
    group.sample_size(20);
    group.bench_function("n60_model_built_once", |b| {
        b.iter(|| model.modes_at(&pose, Sliders::Locked, 6).expect("modes"))
    });
    group.bench_function("n60_frequencies_only", |b| {
        b.iter(|| model.frequencies_at(&pose, Sliders::Locked, 6).expect("frequencies"))
    });
    group.bench_function("n60_from_scratch", |b| {
        b.iter(|| {
            pose_modes(
                &exp.robot,
                &pose,
                Sliders::Locked,
                ModeFamily::Enriched,
                DEFAULT_MODAL_MODES,
                6,
            )
            .expect("modes")
        })
    });
    group.finish();
}

fn map_21x21(c: &mut Criterion) {
    let exp = paper_robot();
    let axis = Axis::parse("--gx", "-0.15:0.15:21").expect("axis");
    let grid = Grid {
        gx: axis,
        gy: axis,
        theta: 0.0,
        sliders: Sliders::Locked,
    };
    let mut group = c.benchmark_group("amm_freqmap");
    group.sample_size(10);
    group.bench_function("21x21_n60", |b| {
        b.iter(|| freqmap(&exp, &grid, 6, Solver::Amm, |_, _| {}).expect("map"))
    });
    group.finish();
}

criterion_group!(benches, one_pose, map_21x21);
criterion_main!(benches);
