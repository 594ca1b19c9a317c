//! Speed of the AMM (`docs/amm.md` section 2): one paper case, N = 25, 0.5 s of motion at the default
//! step, target at most 20 ms on one core. The four paper cases share the catalogue of the tests.
#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, Criterion};
use flexstar_model::ModeFamily;

fn paper_cases(c: &mut Criterion) {
    let mut group = c.benchmark_group("amm_n25_default_step");
    group.sample_size(20);
    for case in [3, 1, 2, 4] {
        for fam in ModeFamily::PAPER {
            if case != 3 && fam != ModeFamily::FreeFree {
                continue;
            }
            let exp = common::paper_case(case);
            let settings = common::settings(fam, 25, None);
            group.bench_function(format!("case{case}_{fam}"), |b| {
                let problem = exp.problem().unwrap();
                b.iter(|| {
                    flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
                        .map(|s| s.response)
                        .unwrap()
                })
            });
        }
    }
    group.finish();
}

/// The accurate model's speed (`docs/amm.md` section 9): one paper case with the defaults (enriched
/// family, full model, automatic N at tol 0.5 %: runs at N = 46, 53), target at most 20 ms on one
/// core; and one run at the N the defaults settle on.
fn accurate_model(c: &mut Criterion) {
    let mut group = c.benchmark_group("amm_accurate_defaults");
    group.sample_size(10);
    for case in [3, 1, 2, 4] {
        let exp = common::paper_case(case);
        let settings = flexstar_model::AmmSettings::accurate();
        inverse_solve(&mut group, &format!("case{case}_auto"), &exp, &settings);
    }
    let exp = common::paper_case(3);
    let fixed = flexstar_model::AmmSettings {
        modes: Some(53),
        ..flexstar_model::AmmSettings::accurate()
    };
    inverse_solve(&mut group, "case3_n53", &exp, &fixed);
    // the run the automatic choice delivers on case 3: N = 53 at its step (tolerance_step(0.5) =
    // 5e-4 s, 1000 steps), without the choice's other runs
    let delivered = flexstar_model::AmmSettings {
        dt: Some(flexstar_amm::tolerance_step(0.5)),
        ..fixed.clone()
    };
    inverse_solve(&mut group, "case3_n53_delivered_step", &exp, &delivered);
    group.finish();
}

/// One benchmark of `group`: the inverse (prescribed-motion) solve of `exp` with `settings`.
fn inverse_solve(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    exp: &flexstar_model::Experiment,
    settings: &flexstar_model::AmmSettings,
) {
    group.bench_function(name, |b| {
        let problem = exp.problem().unwrap();
        b.iter(|| {
            flexstar_amm::solve(&problem, settings, flexstar_drive::SolveRequest::motion())
                .map(|s| s.response)
                .unwrap()
        })
    });
}

/// Direct dynamics (`docs/amm.md` section 10): a direct run (forces of the inverse run fed back,
/// and a 20 Hz servo) against the inverse run of the same case; target at most twice the inverse
/// time.
fn direct_vs_inverse(c: &mut Criterion) {
    use flexstar_drive::{ForceTable, Servo};
    let mut group = c.benchmark_group("amm_direct_vs_inverse");
    group.sample_size(10);
    let paper = common::settings(ModeFamily::FreeFree, 25, None);
    let accurate = flexstar_model::AmmSettings {
        modes: Some(53),
        ..flexstar_model::AmmSettings::accurate()
    };
    for (label, settings) in [("n25_free-free", paper), ("n53_accurate", accurate)] {
        let exp = common::paper_case(3);
        let problem = exp.problem().unwrap();
        let inverse = flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
            .map(|s| s.response)
            .unwrap();
        let fa = (0..inverse.len())
            .map(|k| [inverse.fa[0][k], inverse.fa[1][k], inverse.fa[2][k]])
            .collect();
        let table = ForceTable::new(inverse.t.clone(), fa).unwrap();
        let (kp, kd) = Servo::gains_from_bandwidth(exp.robot.mpp_mpa, 20.0, 0.7);
        let servo = Servo {
            kp: [kp; 3],
            kd: [kd; 3],
            rigid_feedforward: true,
            reference: exp.trajectory.clone(),
            params: exp.robot,
            attached: Default::default(),
        };
        group.bench_function(format!("case3_{label}_inverse"), |b| {
            let problem = exp.problem().unwrap();
            b.iter(|| {
                flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
                    .map(|s| s.response)
                    .unwrap()
            })
        });
        group.bench_function(format!("case3_{label}_direct_forces"), |b| {
            let problem = exp.problem().unwrap();
            b.iter(|| {
                flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::law(&table))
                    .map(|s| s.response)
                    .unwrap()
            })
        });
        group.bench_function(format!("case3_{label}_direct_servo"), |b| {
            let problem = exp.problem().unwrap();
            b.iter(|| {
                flexstar_amm::solve(&problem, &settings, flexstar_drive::SolveRequest::law(&servo))
                    .map(|s| s.response)
                    .unwrap()
            })
        });
    }
    group.finish();
}

/// Payload, damping and load (`docs/amm.md` 11.7): the accurate model (case 3, N = 53) bare and
/// with a payload off G, damping and a load with all three components; target at most 10 % more
/// time.
fn attachments(c: &mut Criterion) {
    use flexstar_model::{Damping, LoadSettings, Payload};
    let mut group = c.benchmark_group("amm_attachments");
    group.sample_size(20);
    let bare = common::paper_case(3);
    let mut loaded = bare.clone();
    loaded.payload = Payload {
        mass: 0.8,
        j: 3e-3,
        offset: [0.04, 0.02],
    };
    loaded.damping = Damping::with_beta(8e-4);
    loaded.load = LoadSettings::polynomials(Some(vec![0.0, 0.0, 12.0]), Some(vec![0.0, -4.0]), Some(vec![0.0, 0.5]));
    // in a vertical plane: the static start and the beams' third-order terms about the sag
    // (docs/amm.md 12.14)
    let mut vertical = bare.clone();
    vertical.gravity.g = [0.0, -9.81];
    let fixed = flexstar_model::AmmSettings {
        modes: Some(53),
        ..flexstar_model::AmmSettings::accurate()
    };
    for (label, exp) in [
        ("bare", &bare),
        ("payload_damping_load", &loaded),
        ("gravity", &vertical),
    ] {
        group.bench_function(format!("case3_n53_{label}"), |b| {
            let problem = exp.problem().unwrap();
            b.iter(|| {
                flexstar_amm::solve(&problem, &fixed, flexstar_drive::SolveRequest::motion())
                    .map(|s| s.response)
                    .unwrap()
            })
        });
    }
    group.finish();
}

/// Friction (`docs/friction.md` 6, 9): the accurate model at its defaults on the four paper cases,
/// without friction and with Coulomb friction in the sleeves (`mu = 0.1`, normal load); target at
/// most 1.5 times the frictionless time.
fn friction(c: &mut Criterion) {
    let mut group = c.benchmark_group("amm_friction");
    group.sample_size(10);
    let settings = flexstar_model::AmmSettings::accurate();
    for case in [1, 2, 3, 4] {
        let bare = common::paper_case(case);
        let mut rubbing = bare.clone();
        rubbing.friction = Some(flexstar_model::Friction {
            mu: flexstar_model::robot_section::PerBeam([0.1; 3]),
            ..Default::default()
        });
        for (label, exp) in [("frictionless", &bare), ("mu0.1", &rubbing)] {
            inverse_solve(&mut group, &format!("case{case}_{label}"), exp, &settings);
        }
    }
    group.finish();
}

criterion_group!(
    benches,
    paper_cases,
    accurate_model,
    direct_vs_inverse,
    attachments,
    friction
);
criterion_main!(benches);
