//! The time step allocates nothing once the workspace exists (its own test binary, so that
//! the counting allocator sees no other test).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use mechanics::{ModelParams, PressureKind, StepParams, Tissue, Workspace};
use phasefield::{init, Lattice, PatchShape};

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

#[allow(unsafe_code)]
// SAFETY: forwards to the system allocator unchanged, only counting calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Rayon's injector queue allocates a block every 63 jobs injected from outside a pool, so
/// the steps run inside one (as `monolayer run` does); everything the step itself needs lives
/// in the [`Workspace`].
#[test]
fn a_warm_step_allocates_nothing() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    pool.install(check_steps);
}

fn check_steps() {
    let lattice = Lattice::new(100, 100);
    let centres = init::positions(lattice, 60, 4.0, &init::Layout::Random { seed: 2 }).unwrap();
    for (margin, pressure) in [
        (12, PressureKind::Paper),
        (12, PressureKind::Interaction),
        (0, PressureKind::Paper),
    ] {
        let cells = init::discs(
            lattice,
            PatchShape::new(lattice, margin).unwrap(),
            &centres,
            4.0,
            2.5,
        );
        let mut t = Tissue::new(cells, ModelParams::paper(0.01).with_pressure(pressure));
        let mut ws = Workspace::new(t.cells());
        let sp = StepParams::new(0.2, 2);
        // Warm-up: starts rayon's pool and its thread-local state.
        for _ in 0..3 {
            t.step(&mut ws, &sp).unwrap();
        }
        let before = ALLOCS.load(Ordering::SeqCst);
        for _ in 0..60 {
            t.step(&mut ws, &sp).unwrap();
        }
        let o = t.observe(&mut ws);
        let after = ALLOCS.load(Ordering::SeqCst);
        assert!(o.v_rms.is_finite());
        assert_eq!(
            after - before,
            0,
            "margin {margin}: {} allocations in 60 steps and one observation",
            after - before
        );
    }
    // With a cell-cycle clock (every cell growing, extrusion and deaths checked, no event
    // due): the clock's work after each step allocates nothing either; only events do.
    let shape = PatchShape::new(lattice, 12).unwrap();
    let cells = init::discs(lattice, shape, &centres, 4.0, 2.5);
    let t = Tissue::new(cells, ModelParams::paper(0.01));
    let clock = mechanics::division::Proliferation::new(0.0, 1.0, 3, &t)
        .with_growth_time(1e12)
        .with_extrusion(0.01)
        .with_death_rate(1e-12);
    let mut t = t.with(clock);
    let mut ws = Workspace::new(t.cells());
    let sp = StepParams::new(0.2, 2);
    for _ in 0..3 {
        t.step(&mut ws, &sp).unwrap();
        t.proliferate(&mut ws);
    }
    let before = ALLOCS.load(Ordering::SeqCst);
    for _ in 0..60 {
        t.step(&mut ws, &sp).unwrap();
        let events = t.proliferate(&mut ws);
        assert!(events.divisions.is_empty() && events.removals.is_empty());
    }
    let after = ALLOCS.load(Ordering::SeqCst);
    assert_eq!(
        after - before,
        0,
        "with a clock: {} allocations in 60 steps",
        after - before
    );
}
