//! The stepping loop allocates nothing: the test binary's global allocator
//! (`alloc_watch`) counts a thread's allocations over a long open- and closed-loop run
//! of each preset.

use rtid::input::{Move, Sine};
use rtid::model::presets;
use rtid::recorder::NullRecorder;
use rtid::sim::Simulation;

use crate::alloc_watch::allocations;

#[test]
fn the_counter_counts() {
    let before = allocations();
    let v = std::hint::black_box(vec![1u8; 64]);
    assert!(allocations() > before && v.len() == 64);
}

#[test]
fn stepping_allocates_nothing() {
    for name in ["worm-gear", "roller-gear-cam"] {
        let p = presets::load(name).unwrap();
        let mut sim = Simulation::with_default_step(&p).unwrap();
        let mut controller = sim.controller(&p).unwrap();
        let mut input = Sine::new(230.0, 5.0, 0.0);
        let step = Move {
            from: 0.0,
            to: 0.1,
            speed: None,
        };
        let before = allocations();
        // 20 000 steps each, with backlash crossings (contact events) included.
        sim.run_open_loop(&mut input, 0.2, &mut NullRecorder)
            .unwrap();
        sim.run_closed_loop(&mut controller, &step, 0.2, &mut NullRecorder)
            .unwrap();
        let after = allocations();
        assert_eq!(after - before, 0, "{name}: {} allocations", after - before);
    }
}

#[test]
fn stepping_the_direct_drive_and_two_mass_topologies_allocates_nothing() {
    let mut two_mass = presets::load("two-mass").unwrap();
    two_mass.theta_bw = 1e-4; // contact events too
    let mut direct_drive = presets::load("direct-drive").unwrap();
    direct_drive.tload = 0.5;
    direct_drive.controller.kpi = 100.0;
    direct_drive.controller.output_delay_periods = 1.0;
    for p in [direct_drive, two_mass] {
        let mut sim = Simulation::with_default_step(&p).unwrap();
        let mut controller = sim.controller(&p).unwrap();
        controller.set_added(0.01);
        let mut input = Sine::new(60.0, 0.5, 0.0);
        let step = Move {
            from: 0.0,
            to: 0.1,
            speed: None,
        };
        let before = allocations();
        sim.run_open_loop(&mut input, 0.2, &mut NullRecorder)
            .unwrap();
        sim.run_closed_loop(&mut controller, &step, 0.2, &mut NullRecorder)
            .unwrap();
        let after = allocations();
        assert_eq!(
            after - before,
            0,
            "{}: {} allocations",
            p.name,
            after - before
        );
    }
}
