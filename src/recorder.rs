//! Where simulation output goes. A [`Recorder`]'s hook does nothing by default, so a
//! cost evaluation that needs only a few numbers never stores a trajectory.

use crate::model::NSTATE;

/// Receives the state after every integration step (and the initial state).
pub trait Recorder {
    /// `y`: the state (see `model::idx`); `motor_torque`: the torque applied over the
    /// step that ended at `t`, N·m.
    #[inline(always)]
    fn record(&mut self, t: f64, y: &[f64; NSTATE], motor_torque: f64) {
        let _ = (t, y, motor_torque);
    }
}

/// Records nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NullRecorder;

impl Recorder for NullRecorder {}

/// One recorded sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub t: f64,
    pub y: [f64; NSTATE],
    pub motor_torque: f64,
}

/// Keeps every `every`-th sample in memory.
#[derive(Clone, Debug)]
pub struct Trace {
    every: usize,
    count: usize,
    pub samples: Vec<Sample>,
}

impl Trace {
    /// Records one sample in `every` (≥ 1).
    pub fn every(every: usize) -> Self {
        Trace {
            every: every.max(1),
            count: 0,
            samples: Vec::new(),
        }
    }
}

impl Recorder for Trace {
    fn record(&mut self, t: f64, y: &[f64; NSTATE], motor_torque: f64) {
        if self.count % self.every == 0 {
            self.samples.push(Sample {
                t,
                y: *y,
                motor_torque,
            });
        }
        self.count += 1;
    }
}
