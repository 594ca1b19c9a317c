//! Speed of the FEM on the paper's cases at the default step (`docs/fem.md` section 6: one paper case at the
//! paper's mesh, 300 elements, in at most 0.15 s on one core; 3000 elements in at most 10 times
//! the 300-element time). Case 2 (s = [t^2, -0.5 t^2, -0.5 t^2], 0.4 s) at 300 and 3000 elements,
//! and cases 1, 3 and 4 (0.5 s each) at 300. Run pinned to one core:
//! `taskset -c 1 cargo bench -p flexstar-fem --features bench --bench paper_case`.
//!
//! Direct dynamics (`docs/fem.md` section 8): case 2 at 300 elements driven by the forces of its own inverse
//! run (written at every solver step, fed back through a `ForceTable`), and by a 20 Hz servo with
//! rigid feedforward: the cost of the three slider unknowns and of evaluating the law at every
//! Newton iteration, against the inverse run above.
//!
//! Payload, damping and load (`docs/fem.md` section 9): case 2 at 300 elements carrying a payload
//! (0.5 kg, J = 2e-3 kg m^2, offset (0.02, -0.01) m), damped (beta = 8e-4 s: zeta 0.01 at 4 Hz)
//! and loaded at G (all three components), against the bare `case2_0.4s_300el` (at most 10 %
//! more).

use criterion::{criterion_group, criterion_main, Criterion};
use flexstar_drive::{ForceTable, Servo};
use flexstar_model::{catalogue, FemSettings};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("fem");
    g.sample_size(10);
    for (name, k, elements) in [
        ("case2_0.4s_300el", 2, 300),
        ("case1_0.5s_300el", 1, 300),
        ("case3_0.5s_300el", 3, 300),
        ("case4_0.5s_300el", 4, 300),
        ("case2_0.4s_3000el", 2, 3000),
    ] {
        let exp = catalogue::paper_case(k);
        let settings = FemSettings {
            elements,
            ..FemSettings::default()
        };
        g.bench_function(name, |b| {
            let problem = exp.problem().unwrap();
            b.iter(|| {
                flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
                    .map(|s| s.response)
                    .unwrap()
            })
        });
    }
    let mut attached = catalogue::paper_case(2);
    attached.payload = flexstar_model::Payload {
        mass: 0.5,
        j: 2e-3,
        offset: [0.02, -0.01],
    };
    attached.damping = flexstar_model::Damping::with_beta(8e-4);
    attached.load = flexstar_model::LoadSettings::polynomials(
        Some(vec![0.0, 0.0, 8.0]),
        Some(vec![0.0, -1.0]),
        Some(vec![0.0, 0.0, 1.0]),
    );
    let settings = FemSettings::default();
    g.bench_function("case2_0.4s_300el_payload_damping_load", |b| {
        let problem = attached.problem().unwrap();
        b.iter(|| {
            flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
                .map(|s| s.response)
                .unwrap()
        })
    });
    let mut exp = catalogue::paper_case(2);
    exp.time.dt_out = flexstar_fem::DEFAULT_DT;
    let settings = FemSettings::default();
    let problem = exp.problem().unwrap();
    let inverse = flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| s.response)
        .unwrap();
    let rows = (0..inverse.len())
        .map(|k| [inverse.fa[0][k], inverse.fa[1][k], inverse.fa[2][k]])
        .collect();
    let table = ForceTable::new(inverse.t.clone(), rows).unwrap();
    g.bench_function("case2_0.4s_300el_inverse_every_step", |b| {
        let problem = exp.problem().unwrap();
        b.iter(|| {
            flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
                .map(|s| s.response)
                .unwrap()
        })
    });
    g.bench_function("case2_0.4s_300el_direct_forces", |b| {
        let problem = exp.problem().unwrap();
        b.iter(|| {
            flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::law(&table))
                .map(|s| s.response)
                .unwrap()
        })
    });
    let (kp, kd) = Servo::gains_from_bandwidth(exp.robot.mpp_mpa, 20.0, 0.7);
    let servo = Servo {
        kp: [kp; 3],
        kd: [kd; 3],
        rigid_feedforward: true,
        reference: exp.trajectory.clone(),
        params: exp.robot,
        attached: Default::default(),
    };
    g.bench_function("case2_0.4s_300el_direct_servo20hz", |b| {
        let problem = exp.problem().unwrap();
        b.iter(|| {
            flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::law(&servo))
                .map(|s| s.response)
                .unwrap()
        })
    });
    g.finish();
}

/// Friction (`docs/friction.md` 6, 8): the four paper cases at 300 elements, without friction and
/// with Coulomb friction in the sleeves (`mu = 0.1`, normal load); target at most 1.5 times the
/// frictionless time.
fn friction(c: &mut Criterion) {
    let mut g = c.benchmark_group("fem_friction");
    g.sample_size(10);
    let settings = FemSettings::default();
    for case in [1, 2, 3, 4] {
        let bare = catalogue::paper_case(case);
        let mut rubbing = bare.clone();
        rubbing.friction = Some(flexstar_model::Friction {
            mu: flexstar_model::robot_section::PerBeam([0.1; 3]),
            ..Default::default()
        });
        for (label, exp) in [("frictionless", &bare), ("mu0.1", &rubbing)] {
            g.bench_function(format!("case{case}_{label}"), |b| {
                let problem = exp.problem().unwrap();
                b.iter(|| {
                    flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
                        .map(|s| s.response)
                        .unwrap()
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench, friction);
criterion_main!(benches);
