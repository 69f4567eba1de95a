//! [`LaneSimulation`]: `L` simulations advanced in lockstep lanes of one
//! `Kernel<L>` — of one model (the frequencies of a sweep) or of `L` parameter sets
//! whose equations have one shape (the points of a sweep, the runs of a batch), open
//! loop step by step or closed loop under a controller per lane.

use super::{checked_drive, describe, diverged, whole_steps, SimError};
use crate::controller::{Controller, Gains};
use crate::input::Trajectory;
use crate::model::drive::idx::*;
use crate::model::{Drive, Kernel, LaneDrive, Params, States, NSTATE};
use crate::recorder::Recorder;

/// Trajectories advanced together by one worker: two AVX2 registers per state
/// (docs/performance.md: 8 measured no faster on the hosts at hand).
pub const LANES: usize = 4;

/// `L` independent simulations, advanced together one step at a time (`Kernel<L>`
/// lanes, so that the compiler vectorises them): of one model
/// ([`LaneSimulation::new`]), or of `L` parameter sets whose equations have one
/// shape ([`LaneSimulation::of`]). Each lane has its own state, clock, table load
/// and motor torque, and can be restarted on its own; lane `l` computes bit for bit
/// what a [`Simulation`](super::Simulation) computes for the same run alone. Every
/// step checks every lane for divergence; an idle lane (at rest, no torque) stays at
/// rest.
#[derive(Clone, Debug)]
pub struct LaneSimulation<const L: usize> {
    drives: [Drive; L],
    lanes: LaneDrive<L>,
    dt: f64,
    steps: [u64; L],
    y: States<L>,
    kernel: Kernel<L>,
    load: [f64; L],
}

impl<const L: usize> LaneSimulation<L> {
    /// `L` tables at rest at zero angles, integrated with step `dt` (checked as by
    /// [`Simulation::new`](super::Simulation::new)).
    pub fn new(params: &Params, dt: f64) -> Result<Self, SimError> {
        Self::with_drives([checked_drive(params, dt)?; L], dt)
    }

    /// `params[l]` in lane `l`, every lane at rest at zero angles and integrated with
    /// step `dt` (checked for each as by [`Simulation::new`](super::Simulation::new)).
    /// The parameter sets must give equations of one shape
    /// ([`crate::model::LaneKey`]); an error names the first that does not.
    pub fn of(params: &[Params; L], dt: f64) -> Result<Self, SimError> {
        let mut drives = Vec::with_capacity(L);
        for p in params {
            drives.push(checked_drive(p, dt)?);
        }
        let drives: [Drive; L] = drives.try_into().expect("one drive per parameter set");
        Self::with_drives(drives, dt)
    }

    fn with_drives(drives: [Drive; L], dt: f64) -> Result<Self, SimError> {
        Ok(LaneSimulation {
            lanes: LaneDrive::gather(&drives)?,
            drives,
            dt,
            steps: [0; L],
            y: [[0.0; L]; NSTATE],
            kernel: Kernel::default(),
            load: drives.map(|d| d.tload()),
        })
    }

    /// The integration step, s.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The compiled model of lane `l`.
    pub fn drive(&self, l: usize) -> &Drive {
        &self.drives[l]
    }

    /// Starts a new run in lane `l` at t = 0 from state `y` (slots the topology does
    /// not integrate follow, [`Drive::mirror`]) under the external table torque `load`
    /// (N·m; `Tload` adds to it), as a new [`Simulation`](super::Simulation) with
    /// [`set_state`](super::Simulation::set_state) and
    /// [`set_load`](super::Simulation::set_load) would.
    pub fn start(&mut self, l: usize, mut y: [f64; NSTATE], load: f64) {
        self.drives[l].mirror(&mut y);
        for (i, v) in y.into_iter().enumerate() {
            self.y[i][l] = v;
        }
        self.kernel.reset_lane(l);
        self.steps[l] = 0;
        self.load[l] = load + self.drives[l].tload();
    }

    /// Simulated time of lane `l`, s.
    pub fn time(&self, l: usize) -> f64 {
        self.steps[l] as f64 * self.dt
    }

    /// The state of lane `l`.
    pub fn state(&self, l: usize) -> [f64; NSTATE] {
        self.y.map(|s| s[l])
    }

    /// Contact events split so far, all lanes.
    pub fn contact_events(&self) -> u64 {
        self.kernel.events()
    }

    /// One step of every lane; `motor[s][l]` is lane `l`'s motor torque at the
    /// step's start, middle and end (see [`TorqueInput`](crate::input::TorqueInput)).
    /// A diverged lane stops the run with its time and state.
    #[inline]
    pub fn step(&mut self, motor: &[[f64; L]; 3]) -> Result<(), SimError> {
        self.kernel
            .step(&self.lanes, &mut self.y, motor, &self.load, self.dt);
        self.tick();
        match diverged(&self.y) {
            None if crate::interrupt::at_step(self.steps[0]) => {
                Err(SimError::Interrupted { time: self.time(0) })
            }
            None => Ok(()),
            Some(l) => Err(self.diverged_error(l)),
        }
    }

    /// A controller for lane `l`'s table (`params`: that lane's), at rest at its
    /// current angles, as [`Simulation::controller`](super::Simulation::controller).
    pub fn controller(&self, l: usize, params: &Params) -> Result<Controller, SimError> {
        super::check_control_period(params)?;
        Ok(Controller::new(
            Gains::new(params)?,
            self.y[THETA_M][l],
            self.y[THETA_T][l],
        ))
    }

    /// A controller for each lane (`params[l]` for lane `l`), as
    /// [`LaneSimulation::controller`].
    pub fn controllers(&self, params: &[Params; L]) -> Result<[Controller; L], SimError> {
        let mut out = Vec::with_capacity(L);
        for (l, p) in params.iter().enumerate() {
            out.push(self.controller(l, p)?);
        }
        Ok(out.try_into().expect("one per lane"))
    }

    /// Runs `duration` seconds of every lane under its controller, all following
    /// `trajectory` (table angle command, rad or m), each controller updating every
    /// control period and holding its output: lane `l` as
    /// [`Simulation::run_closed_loop`](super::Simulation::run_closed_loop) would run
    /// it alone, every step reported to `recorders[l]`. Lanes with an error in
    /// `failed` are skipped (at rest, no torque, not recorded); a lane that diverges
    /// gets its error there and is put to rest, and the others go on.
    pub fn run_closed_loop<T: Trajectory + ?Sized, R: Recorder>(
        &mut self,
        (controllers, recorders): (&mut [Controller; L], &mut [R; L]),
        trajectory: &T,
        duration: f64,
        failed: &mut [Option<SimError>; L],
    ) -> Result<(), SimError> {
        let tc = controllers[0].gains().tc;
        let per =
            whole_steps(tc, self.dt).ok_or(SimError::ControlPeriod { tc, dt: self.dt })? as u64;
        if let Some(c) = controllers.iter().find(|c| c.gains().tc != tc) {
            let tc = c.gains().tc;
            return Err(SimError::ControlPeriod { tc, dt: self.dt });
        }
        for l in 0..L {
            if self.steps[l] == 0 && failed[l].is_none() {
                recorders[l].record(0.0, &self.state(l), controllers[l].torque());
            }
        }
        let run = (controllers, recorders);
        // The form is chosen once, outside the step loop (kernel.rs).
        if self.lanes.form == crate::model::drive::Form::Rigid {
            self.closed_loop::<true, T, R>(run, trajectory, duration, per, failed);
        } else {
            self.closed_loop::<false, T, R>(run, trajectory, duration, per, failed);
        }
        Ok(())
    }

    fn closed_loop<const RIGID: bool, T: Trajectory + ?Sized, R: Recorder>(
        &mut self,
        (controllers, recorders): (&mut [Controller; L], &mut [R; L]),
        trajectory: &T,
        duration: f64,
        per: u64,
        failed: &mut [Option<SimError>; L],
    ) {
        let n = (duration / self.dt).round() as u64;
        for _ in 0..n {
            let mut u = [0.0; L];
            for (l, c) in controllers.iter_mut().enumerate() {
                if failed[l].is_some() {
                    continue;
                }
                if self.steps[l] % per == 0 {
                    let t = self.time(l);
                    c.update(trajectory.angle(t), self.y[THETA_M][l], self.y[THETA_T][l]);
                }
                u[l] = c.torque();
            }
            let (d, y, load) = (&self.lanes, &mut self.y, &self.load);
            if RIGID {
                self.kernel.step_rigid(d, y, &[u; 3], load, self.dt);
            } else {
                self.kernel.step_meshed(d, y, &[u; 3], load, self.dt);
            }
            self.tick();
            if diverged(&self.y).is_some() {
                self.stop_diverged(failed);
            }
            if crate::interrupt::at_step(self.steps[0]) {
                self.stop_all(failed);
                return;
            }
            for (l, r) in recorders.iter_mut().enumerate() {
                if failed[l].is_none() {
                    r.record(self.time(l), &self.state(l), u[l]);
                }
            }
        }
    }

    /// Every lane's clock advances one step.
    #[inline(always)]
    fn tick(&mut self) {
        for s in &mut self.steps {
            *s += 1;
        }
    }

    /// Records the error of every diverged lane in `failed` and puts the lane to
    /// rest at zero angles without load (so it stays there), its clock kept.
    #[cold]
    fn stop_diverged(&mut self, failed: &mut [Option<SimError>; L]) {
        while let Some(l) = diverged(&self.y) {
            failed[l] = Some(self.diverged_error(l));
            for i in 0..NSTATE {
                self.y[i][l] = 0.0;
            }
            self.kernel.reset_lane(l);
            self.load[l] = 0.0;
        }
    }

    /// Records an interruption in `failed` for every lane still running.
    #[cold]
    fn stop_all(&self, failed: &mut [Option<SimError>; L]) {
        for (l, f) in failed.iter_mut().enumerate() {
            if f.is_none() {
                *f = Some(SimError::Interrupted { time: self.time(l) });
            }
        }
    }

    fn diverged_error(&self, l: usize) -> SimError {
        SimError::Diverged {
            time: self.time(l),
            state: describe(&self.state(l)),
        }
    }
}
