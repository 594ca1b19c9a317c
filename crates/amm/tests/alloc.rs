//! "No allocation inside the time loop": the number of heap allocations of a
//! solve does not depend on the number of steps (workspaces and outputs are sized once).

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use flexstar_model::{AmmModel, ModeFamily};

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
