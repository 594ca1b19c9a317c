//! "No allocation inside the time loop": the number of heap allocations of a
//! solve does not depend on the number of steps (workspaces and outputs are sized once), and a
//! step past the first few allocates nothing, whatever the model and attachments.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use flexstar_model::{AmmModel, Beam, ModeFamily, Problem, Robot, RobotParams};

/// Counts allocations made by the current thread (the test harness's other threads are ignored).
struct Counting;

thread_local! {
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        COUNT.with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        COUNT.with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations(dt: f64, model: AmmModel) -> usize {
    let exp = common::paper_case(3);
    let mut s = common::settings(ModeFamily::FreeFree, 25, Some(dt));
    if model == AmmModel::Full {
        // the accurate model's own per-step work: junction shapes, geometric stiffness products
        s.family = ModeFamily::Enriched;
        s.model = model;
    }
    s.snapshots = vec![0.2];
    let before = COUNT.with(|c| c.get());
    let r = common::motion_response(&exp, &s).unwrap();
    let after = COUNT.with(|c| c.get());
    assert_eq!(r.len(), 501);
    after - before
}

#[test]
fn allocations_do_not_grow_with_the_number_of_steps() {
    for model in [AmmModel::Paper, AmmModel::Full] {
        // faer's matrix products keep a per-thread scratch buffer, allocated on first use
        allocations(1e-3, model);
        let coarse = allocations(1e-3, model); // 500 steps
        let fine = allocations(1e-4, model); // 5000 steps
        assert_eq!(
            coarse, fine,
            "{model}: {coarse} allocations for 500 steps, {fine} for 5000"
        );
        // setup only: modes (the enriched family's quadrature rows), workspaces, 101 shape rows,
        // output columns, snapshots
        assert!(coarse < 4000, "{model}: {coarse} allocations for one solve");
    }
}

/// Allocations over the steps `warm_up + 1 ..= warm_up + k` of a stepwise run of `exp` (output
/// rows recorded among them), counted with [`flexstar_amm::solve_stepwise`]'s hook.
fn allocations_per_steps(problem: &Problem, s: &flexstar_model::AmmSettings, warm_up: usize, k: usize) -> usize {
    let (mut start, mut end) = (None, None);
    let r = flexstar_amm::solve_stepwise(problem, s, |step| {
        if step == warm_up {
            start = Some(COUNT.with(|c| c.get()));
        } else if step == warm_up + k {
            end = Some(COUNT.with(|c| c.get()));
        }
    })
    .unwrap();
    assert!(r.len() > 1);
    end.expect("a run long enough") - start.unwrap()
}

#[test]
fn a_step_allocates_nothing() {
    use flexstar_model::{Damping, Friction, LoadSettings, Payload};
    let paper = common::settings(ModeFamily::FreeFree, 25, None);
    let accurate = flexstar_model::AmmSettings {
        modes: Some(53),
        ..flexstar_model::AmmSettings::accurate()
    };
    let bare = common::paper_case(3);
    let mut attached = bare.clone();
    attached.payload = Payload {
        mass: 0.8,
        j: 3e-3,
        offset: [0.04, 0.02],
    };
    attached.damping = Damping::rayleigh(2.0, 8e-4);
    attached.load = LoadSettings::polynomials(Some(vec![0.0, 0.0, 12.0]), Some(vec![0.0, -4.0]), Some(vec![0.0, 0.5]));
    let mut weighed = bare.clone();
    weighed.gravity.g = [0.0, -9.81];
    let mut rubbing = bare.clone();
    rubbing.friction = Some(Friction {
        mu: flexstar_model::robot_section::PerBeam([0.1; 3]),
        ..Default::default()
    });
    let unequal = bare.problem().unwrap().with_robot(unequal_beams()).unwrap();
    for (label, problem, s) in [
        ("paper model", bare.problem().unwrap(), &paper),
        ("accurate model", bare.problem().unwrap(), &accurate),
        ("payload, damping, load", attached.problem().unwrap(), &accurate),
        ("gravity", weighed.problem().unwrap(), &accurate),
        ("friction", rubbing.problem().unwrap(), &accurate),
        ("unequal beams", unequal, &accurate),
    ] {
        // 200 steps of warm-up (the first solves, faer's scratch), then 600 steps with 100 output rows
        let n = allocations_per_steps(&problem, s, 200, 600);
        assert_eq!(n, 0, "{label}: {n} allocations in 600 steps");
    }
}

/// The paper's robot with three different beams (the per-beam layout, `docs/amm.md` 13).
fn unequal_beams() -> Robot {
    let p = RobotParams::paper();
    let beams = std::array::from_fn(|i| Beam {
        youngs_modulus: p.e * [1.0, 1.2, 0.85][i],
        second_moment: p.i,
        axial_stiffness: p.ea(),
        mass_per_length: p.rho * [1.0, 1.15, 0.9][i],
        length: p.l * [1.0, 0.92, 1.06][i],
        sleeve_length: p.lp,
        sleeve_mass: p.mpp_mpa,
        sleeve_inertia: p.jp,
        weld_angle: (120.0 * i as f64).to_radians(),
    });
    Robot::new(
        beams,
        flexstar_model::ActuatorAxis::from_sides([0.626, 0.618, 0.631]).unwrap(),
    )
    .unwrap()
}
