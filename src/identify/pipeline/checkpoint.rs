//! What `--resume` needs: the problem's identity (a typed fingerprint: a checkpoint of
//! another problem is refused, naming what differs), the stage reached, the starts
//! done so far and the evaluations counted. Written atomically after every finished
//! start and at the end.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::identify::config::Config;
use crate::identify::plan::Plan;
use crate::identify::result::starts::StartRecord;
use crate::identify::search::problem::Monitor;
use crate::identify::search::settings::Method;
use crate::identify::space::ParamSpace;
use crate::identify::Termination;

/// The identity of an identification problem.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fingerprint {
    /// The experiment files, in order.
    pub experiments: Vec<String>,
    pub weights: Vec<f64>,
    /// Each experiment's chosen objectives (`None`: its kind's defaults).
    pub objectives: Vec<Option<Vec<String>>>,
    pub fitted: Vec<String>,
    pub bounds: Vec<[f64; 2]>,
    pub start: Vec<f64>,
    pub method: Method,
    pub starts: usize,
    pub seed: u64,
    pub stages: usize,
    /// The parameter set the others are held at (its JSON): the same names fitted
    /// with other values held are another problem.
    #[serde(default)]
    pub held: String,
    /// Each experiment's files' SHA-256 (manifest, then data file): the same paths
    /// holding other data are another problem.
    #[serde(default)]
    pub data: Vec<String>,
}

impl Fingerprint {
    /// The fingerprint of `config` under `plan` in `space`.
    pub fn of(config: &Config, plan: &Plan, space: &ParamSpace) -> Fingerprint {
        let first = &plan.stages[0].settings;
        Fingerprint {
            experiments: config
                .experiments
                .iter()
                .map(|e| e.source.clone())
                .collect(),
            weights: config.experiments.iter().map(|e| e.weight).collect(),
            objectives: config
                .experiments
                .iter()
                .map(|e| {
                    e.objectives
                        .as_ref()
                        .map(|o| o.iter().map(|k| k.name().to_string()).collect())
                })
                .collect(),
            fitted: space.names.iter().map(|n| n.to_string()).collect(),
            bounds: space.bounds.iter().map(|b| [b.lo, b.hi]).collect(),
            start: space.start.clone(),
            method: first.method,
            starts: first.starts,
            seed: first.seed,
            stages: plan.stages.len(),
            held: serde_json::to_string(&config.base).unwrap_or_default(),
            data: config
                .experiments
                .iter()
                .flat_map(|e| [Some(&e.experiment.path), e.experiment.data_path.as_ref()])
                .flatten()
                .map(|p| crate::io::provenance::sha256(p).unwrap_or_default())
                .collect(),
        }
    }

    /// The first field in which `other` differs, if any.
    pub fn difference(&self, other: &Fingerprint) -> Option<&'static str> {
        let fields: [(&'static str, bool); 12] = [
            ("the experiments", self.experiments == other.experiments),
            ("the weights", self.weights == other.weights),
            ("the objectives", self.objectives == other.objectives),
            ("the fitted parameters", self.fitted == other.fitted),
            ("the bounds", self.bounds == other.bounds),
            ("the start values", self.start == other.start),
            ("the method", self.method == other.method),
            ("the number of starts", self.starts == other.starts),
            ("the seed", self.seed == other.seed),
            ("the stages (the model)", self.stages == other.stages),
            ("the parameters held", self.held == other.held),
            ("the experiment files' contents", self.data == other.data),
        ];
        fields.into_iter().find(|(_, same)| !same).map(|(f, _)| f)
    }
}

/// A checkpoint file's content.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Checkpoint {
    pub fingerprint: Fingerprint,
    /// Stage reached (0: the search; 1: the nonlinear corrections).
    pub stage: usize,
    /// The starts of that stage done so far.
    pub starts: Vec<StartRecord>,
    /// The result of the finished search, once the corrections have begun.
    pub stage0_best: Option<Vec<f64>>,
    pub evaluations: usize,
    /// The search's best evaluation so far: a start's result is the solver's point,
    /// but the search's result is its best evaluation (a difference step's point may
    /// cost less), which a resume must not lose — an interruption inside the first
    /// stage's starts resumed to Ciw 0.32 against 0.15 without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub best: Option<SavedBest>,
}

/// The best evaluation of a stage so far: its cost and the fitted parameters' values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SavedBest {
    pub cost: f64,
    pub values: Vec<f64>,
}

/// Why a checkpoint cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CheckpointError {
    #[error("resuming needs a checkpoint file")]
    NoFile,
    #[error("cannot read the checkpoint {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path} is not an rtid checkpoint: {message}")]
    Parse { path: PathBuf, message: String },
    #[error("{path} belongs to another problem ({field} differ)")]
    OtherProblem { path: PathBuf, field: &'static str },
    #[error("{path}: the checkpoint's stage is {stage}, but the problem has {stages} (stage 0 the search, 1 the corrections): the file is corrupted")]
    Stage {
        path: PathBuf,
        stage: usize,
        stages: usize,
    },
    #[error("{path}: the checkpoint holds {found} values for {expected} fitted parameters")]
    Values {
        path: PathBuf,
        found: usize,
        expected: usize,
    },
}

impl Checkpoint {
    /// A fresh checkpoint of the problem `fingerprint`.
    pub fn new(fingerprint: Fingerprint) -> Checkpoint {
        Checkpoint {
            fingerprint,
            stage: 0,
            starts: Vec::new(),
            stage0_best: None,
            evaluations: 0,
            best: None,
        }
    }

    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        let text = crate::io::json::pretty(self).map_err(std::io::Error::other)?;
        crate::io::atomic::write(path, text.as_bytes())
    }

    /// Reads a checkpoint of the problem `expected`: refused, naming what differs,
    /// if it belongs to another one, or if its values do not fit the problem.
    pub fn read(path: &Path, expected: &Fingerprint) -> Result<Checkpoint, CheckpointError> {
        let text = crate::io::read_input(path).map_err(|source| CheckpointError::Read {
            path: path.into(),
            source,
        })?;
        let c: Checkpoint = serde_json::from_str(crate::io::without_bom(&text)).map_err(|e| {
            CheckpointError::Parse {
                path: path.into(),
                message: e.to_string(),
            }
        })?;
        if let Some(field) = c.fingerprint.difference(expected) {
            return Err(CheckpointError::OtherProblem {
                path: path.into(),
                field,
            });
        }
        if c.stage >= c.fingerprint.stages {
            return Err(CheckpointError::Stage {
                path: path.into(),
                stage: c.stage,
                stages: c.fingerprint.stages,
            });
        }
        c.check_sizes(path)?;
        Ok(c.without_costless_results())
    }

    /// The checkpoint with each finished start that has no cost (a file edited by
    /// hand, or a start that never met a finite cost) marked interrupted, so that it
    /// runs again from its result: the resumed search ranks the starts by their costs,
    /// and with none it would report nothing evaluated.
    fn without_costless_results(mut self) -> Checkpoint {
        for s in &mut self.starts {
            if s.result.is_some() && !s.cost.is_some_and(|c| c >= 0.0) {
                s.termination = Termination::Interrupted;
            }
        }
        self
    }

    /// Every stored point has one value per fitted parameter.
    fn check_sizes(&self, path: &Path) -> Result<(), CheckpointError> {
        let expected = self.fingerprint.fitted.len();
        let points = self
            .starts
            .iter()
            .flat_map(|s| [Some(&s.initial), s.result.as_ref()])
            .chain([self.stage0_best.as_ref()])
            .chain([self.best.as_ref().map(|b| &b.values)])
            .flatten();
        for v in points {
            if v.len() != expected || v.iter().any(|x| !x.is_finite()) {
                return Err(CheckpointError::Values {
                    path: path.into(),
                    found: v.len(),
                    expected,
                });
            }
        }
        Ok(())
    }
}

/// The monitor's best evaluation, to save.
fn saved(monitor: &Monitor) -> Option<SavedBest> {
    monitor.best().map(|b| SavedBest {
        cost: b.cost,
        values: b.values,
    })
}

/// The checkpoint of a running identification: kept in memory, written to its file
/// (if any) after every finished start, when a stage begins and at the end. Shared
/// by the parallel starts.
pub struct Checkpointer {
    path: Option<PathBuf>,
    state: std::sync::Mutex<Checkpoint>,
}

impl Checkpointer {
    /// A fresh checkpoint of `fingerprint`, or the one at `path` when `resume` is set
    /// and the file exists (refused if it belongs to another problem).
    pub fn open(
        path: Option<&Path>,
        resume: bool,
        fingerprint: Fingerprint,
    ) -> Result<Checkpointer, CheckpointError> {
        if resume && path.is_none() {
            return Err(CheckpointError::NoFile);
        }
        let state = match path {
            Some(p) if resume && p.exists() => Checkpoint::read(p, &fingerprint)?,
            _ => Checkpoint::new(fingerprint),
        };
        Ok(Checkpointer {
            path: path.map(Path::to_path_buf),
            state: std::sync::Mutex::new(state),
        })
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Checkpoint> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// A copy of the current checkpoint.
    pub(crate) fn snapshot(&self) -> Checkpoint {
        self.lock().clone()
    }

    /// Records a finished (or interrupted) start, the stage's best evaluation so far
    /// and the evaluations counted, and writes the file. A failure to write is not
    /// fatal here: the final write reports it.
    pub(crate) fn save_start(&self, record: &StartRecord, monitor: &Monitor) {
        let mut c = self.lock();
        c.starts.retain(|s| s.index != record.index);
        c.starts.push(record.clone());
        c.evaluations = monitor.evaluations();
        c.best = saved(monitor);
        if let Some(p) = &self.path {
            let _ = c.write(p);
        }
    }

    /// Stage `k` begins from `best` (the search's result): its starts start afresh.
    pub(crate) fn enter_stage(&self, k: usize, best: &[f64], evaluations: usize) {
        let mut c = self.lock();
        c.stage = k;
        c.stage0_best = Some(best.to_vec());
        c.starts.clear();
        c.best = None;
        c.evaluations = evaluations;
        if let Some(p) = &self.path {
            let _ = c.write(p);
        }
    }

    /// The final write, with the evaluations counted and (in the search) the best
    /// evaluation; the error message if it failed.
    pub fn finish(&self, monitor: &Monitor) -> Option<(String, String)> {
        let mut c = self.lock();
        c.evaluations = monitor.evaluations();
        if c.stage == 0 {
            c.best = saved(monitor);
        }
        let p = self.path.as_ref()?;
        c.write(p)
            .err()
            .map(|e| (p.display().to_string(), e.to_string()))
    }
}
