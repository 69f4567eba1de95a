//! Sensitivity sweeps: how the resonances, the ISO 230-2 values, the fluctuation or
//! the torque change when parameters change, and which parameter matters most.
//!
//! A [`Sweep`] is a design ([`designs`]: full grid, local derivatives, Morris
//! trajectories or Saltelli's Sobol sampling) over factors ([`spec`]: registry
//! parameters with ranges) around a base parameter set, and the outputs to compute
//! at each point ([`outputs`]: the virtual experiments, exact linear ones where the
//! output allows). [`run`] evaluates the points in parallel (rayon, one point per
//! task) and streams each finished row to the CSV file ([`stream`]), so an
//! interrupted sweep resumes where it stopped and a large one splits into shards for
//! a job array. [`analysis`] turns the finished rows into local sensitivities,
//! Morris μ*/σ or Sobol S1/ST with bootstrap intervals (drawn by `report::sweep`).
//!
//! Rows are deterministic functions of (design, seed, index): the final file of a
//! straight run, of a resumed one and of merged shards are the same bytes.

pub mod analysis;
pub mod designs;
pub mod local;
pub mod morris;
pub mod outputs;
pub mod sobol;
pub mod spec;
pub mod stream;

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use ndarray::Array2;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::model::{registry, Params};
pub use designs::{Design, DesignError, Method};
pub use outputs::{Evaluator, Output, TestLength};
pub use spec::{Factor, Scale, SpecError};
pub use stream::{Shard, StreamError};

/// What a sweep computes: written as the `# config` line of its file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sweep {
    pub method: Method,
    pub seed: u64,
    pub factors: Vec<Factor>,
    pub outputs: Vec<Output>,
    pub tests: TestLength,
    /// The base parameter set (every factor replaces one of its values).
    pub params: Params,
}

/// Why a sweep cannot run or be analysed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SweepError {
    #[error(transparent)]
    Spec(#[from] SpecError),
    #[error(transparent)]
    Design(#[from] DesignError),
    #[error(transparent)]
    Stream(#[from] StreamError),
    #[error(transparent)]
    Params(#[from] crate::model::ParamError),
    #[error("{path}: the `# config` line does not describe a sweep: {reason}")]
    Config { path: String, reason: String },
    #[error("no output requested: give --outputs, e.g. resonances,peak_gain")]
    NoOutputs,
    #[error("{missing} of the {total} design points have no row (first: index {first}); unfinished: {files}: finish each with --resume")]
    Incomplete {
        missing: usize,
        total: usize,
        first: usize,
        /// The files the missing points belong to, each with its count.
        files: String,
    },
}

/// The column suffix of a registry unit (`N·m/rad` → `nm_per_rad`).
pub(crate) fn unit_suffix(unit: &str) -> String {
    match unit {
        "-" => String::new(),
        "kg·m²" => "kg_m2".into(),
        "N·m·s/rad" => "nms_per_rad".into(),
        "N·s/m" => "ns_per_m".into(),
        "N·m" => "nm".into(),
        "N·m/rad" => "nm_per_rad".into(),
        "N/m" => "n_per_m".into(),
        "1/s" => "per_s".into(),
        "rad/s" => "rad_per_s".into(),
        "1/rev" => "per_rev".into(),
        other => other
            .replace(['·', ' '], "")
            .replace('/', "_per_")
            .replace('²', "2")
            .to_lowercase(),
    }
}

/// A factor's CSV column: its name and unit (`Kw_nm_per_rad`, `theta_bw_rad`, `Rw`).
pub(crate) fn factor_column(name: &str) -> String {
    match registry::spec(name).map(|s| unit_suffix(s.unit)) {
        Ok(suffix) if !suffix.is_empty() => format!("{name}_{suffix}"),
        _ => name.to_string(),
    }
}

impl Sweep {
    /// A sweep, checked: the factors are registry parameters of `params`' topology and
    /// the design can be built.
    pub fn new(
        params: Params,
        factors: Vec<Factor>,
        method: Method,
        outputs: Vec<Output>,
        tests: TestLength,
        seed: u64,
    ) -> Result<Sweep, SweepError> {
        params.validate()?;
        if outputs.is_empty() {
            return Err(SweepError::NoOutputs);
        }
        let sweep = Sweep {
            method,
            seed,
            factors,
            outputs,
            tests,
            params,
        };
        sweep.design()?;
        Ok(sweep)
    }

    /// The sweep described by a file's `# config` line.
    pub(crate) fn from_config(config: &str, path: &Path) -> Result<Sweep, SweepError> {
        serde_json::from_str(config).map_err(|e| SweepError::Config {
            path: path.display().to_string(),
            reason: e.to_string(),
        })
    }

    /// The `# config` line's JSON.
    pub fn config(&self) -> String {
        // Invariant: serde_json fails only on a map with keys other than strings or a
        // Serialize impl that errs; a sweep has derived impls and string-keyed maps.
        serde_json::to_string(self).expect("a sweep serialises")
    }

    /// Base value of each factor.
    pub(crate) fn base_values(&self) -> Result<Vec<f64>, SweepError> {
        self.factors
            .iter()
            .map(|f| {
                let spec = registry::spec(&f.name)?;
                spec.get(&self.params).ok_or(SweepError::Params(
                    crate::model::ParamError::NotApplicable { name: spec.name },
                ))
            })
            .collect()
    }

    /// The design points.
    pub fn design(&self) -> Result<Design, SweepError> {
        Ok(Design::new(
            &self.method,
            &self.factors,
            &self.base_values()?,
            self.seed,
        )?)
    }

    /// What computes the outputs.
    pub fn evaluator(&self) -> Evaluator {
        Evaluator {
            outputs: self.outputs.clone(),
            tests: self.tests,
            topology: self.params.topology,
        }
    }

    /// Output columns (units in the names).
    pub fn output_columns(&self) -> Vec<String> {
        self.evaluator().columns()
    }

    /// Every column of the file: index, factors, outputs, error.
    pub fn columns(&self) -> Vec<String> {
        std::iter::once("index".to_string())
            .chain(self.factors.iter().map(|f| factor_column(&f.name)))
            .chain(self.output_columns())
            .chain(std::iter::once("error".to_string()))
            .collect()
    }

    /// The parameter set at design point `values`.
    pub(crate) fn params_at(&self, values: &[f64]) -> Result<Params, crate::model::ParamError> {
        let mut p = self.params.clone();
        for (f, &v) in self.factors.iter().zip(values) {
            p.set(&f.name, v)?;
        }
        Ok(p)
    }

    /// The rows of design points `indices` (fields as written to the file), their
    /// nonlinear tests run together in the kernel's lanes where the points allow
    /// ([`Evaluator::evaluate_batch`]); each row is what the point gives alone.
    pub fn rows(
        &self,
        design: &Design,
        evaluator: &Evaluator,
        indices: &[usize],
    ) -> Vec<Vec<String>> {
        let values: Vec<Vec<f64>> = indices
            .iter()
            .map(|&i| design.values.row(i).to_vec())
            .collect();
        let sets = values
            .iter()
            .map(|v| self.params_at(v).map_err(outputs::OutputError::from))
            .collect();
        let results = crate::sim::batch::on_valid(sets, |sets| evaluator.evaluate_batch(sets));
        let n_out = evaluator.columns().len();
        indices
            .iter()
            .zip(values)
            .zip(results)
            .map(|((&index, values), result)| row(index, &values, n_out, result))
            .collect()
    }
}

/// The fields of design point `index` at `values` with its outputs (`n_out`
/// columns) or the reason they are missing.
fn row(
    index: usize,
    values: &[f64],
    n_out: usize,
    result: Result<Vec<Option<f64>>, outputs::OutputError>,
) -> Vec<String> {
    let mut row = Vec::with_capacity(2 + values.len() + n_out);
    row.push(index.to_string());
    row.extend(values.iter().map(|v| v.to_string()));
    match result {
        Ok(out) => {
            row.extend(
                out.iter()
                    .map(|v| v.map_or(String::new(), |v| v.to_string())),
            );
            row.push(String::new());
        }
        Err(e) => {
            row.extend(std::iter::repeat(String::new()).take(n_out));
            row.push(e.to_string());
        }
    }
    row
}

/// How [`run`] proceeds.
pub struct RunOptions<'a> {
    /// Continue an existing file, computing only its missing rows.
    pub resume: bool,
    /// Replace an existing file.
    pub overwrite: bool,
    /// Compute only this slice of the design.
    pub shard: Option<Shard>,
    /// Stop after computing this many rows (a test's interruption; `None`: all).
    pub limit: Option<usize>,
    /// Called after each row is written (progress).
    pub on_row: &'a (dyn Fn() + Sync),
}

impl Default for RunOptions<'_> {
    fn default() -> Self {
        RunOptions {
            resume: false,
            overwrite: false,
            shard: None,
            limit: None,
            on_row: &|| {},
        }
    }
}

/// What [`run`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct RunReport {
    /// Design points in this file (the shard's, or all).
    pub total: usize,
    /// Rows found in the file when resuming.
    pub resumed: usize,
    /// Rows computed now.
    pub computed: usize,
    /// Rows whose outputs could not be computed (their `error` column says why).
    pub failed: usize,
    /// Whether every row is there (the file is then sorted and final).
    pub complete: bool,
}

/// Runs (or resumes) `sweep` into `out` (module docs).
pub fn run(sweep: &Sweep, out: &Path, opts: &RunOptions) -> Result<RunReport, SweepError> {
    let design = sweep.design()?;
    let evaluator = sweep.evaluator();
    let header = stream::header(&sweep.config(), opts.shard, &sweep.columns());
    let (journal, done) = stream::Journal::open(out, &header, opts.resume, opts.overwrite)?;
    let mine: Vec<usize> = (0..design.len())
        .filter(|&i| opts.shard.map_or(true, |s| s.contains(i)))
        .collect();
    if let Some(&stray) = done.keys().find(|i| mine.binary_search(i).is_err()) {
        return Err(SweepError::Stream(StreamError::BadFile {
            path: out.into(),
            reason: format!("row {stray} is not a point of this sweep or shard"),
        }));
    }
    check_design_values(&design, &done, |_| out)?;
    let resumed = done.len();
    let mut todo: Vec<usize> = mine
        .iter()
        .copied()
        .filter(|i| !done.contains_key(i))
        .collect();
    if let Some(limit) = opts.limit {
        todo.truncate(limit);
    }
    let journal = Mutex::new(journal);
    let rows = Mutex::new(done);
    // Points in batches of up to LANES per task (the kernel's lanes), fewer when
    // that leaves a worker idle.
    let per_task = todo
        .len()
        .div_ceil(rayon::current_num_threads())
        .clamp(1, crate::sim::LANES);
    let computed = AtomicUsize::new(0);
    todo.par_chunks(per_task)
        .try_for_each(|chunk| -> Result<(), StreamError> {
            if crate::interrupt::requested() {
                return Ok(());
            }
            let batch = sweep.rows(&design, &evaluator, chunk);
            // Rows of a batch a stop request cut short are not the points' outputs.
            if crate::interrupt::requested() {
                return Ok(());
            }
            for (&i, row) in chunk.iter().zip(batch) {
                journal
                    .lock()
                    .expect("no panic holds the lock")
                    .append(&row)?;
                rows.lock().expect("no panic holds the lock").insert(i, row);
                computed.fetch_add(1, Ordering::Relaxed);
                (opts.on_row)();
            }
            Ok(())
        })?;
    drop(journal);
    let rows = rows.into_inner().expect("no panic holds the lock");
    let error_col = sweep.columns().len() - 1;
    let failed = rows.values().filter(|r| !r[error_col].is_empty()).count();
    let complete = rows.len() == mine.len();
    if complete {
        stream::finish(out, &header, &rows)?;
    }
    Ok(RunReport {
        total: mine.len(),
        resumed,
        computed: computed.into_inner(),
        failed,
        complete,
    })
}

/// Checks that the factor values of each row read from a file are the design's at
/// its index, as written (`file_of(i)`: the file row `i` came from). A row edited by
/// hand or left by another design would otherwise be analysed as this one's.
fn check_design_values<'a>(
    design: &Design,
    rows: &BTreeMap<usize, Vec<String>>,
    file_of: impl Fn(usize) -> &'a Path,
) -> Result<(), StreamError> {
    for (&i, row) in rows {
        if i >= design.len() {
            continue;
        }
        let expected = design.values.row(i);
        let written = row.iter().skip(1).take(expected.len());
        if !expected.iter().map(|v| v.to_string()).eq(written.cloned()) {
            return Err(StreamError::BadFile {
                path: file_of(i).to_path_buf(),
                reason: format!(
                    "row {i}: its factor values are not this sweep's design point {i} \
                     (edited by hand, or from another design): remove the row or the file"
                ),
            });
        }
    }
    Ok(())
}

/// Reads a finished sweep file (or merges shard files) and checks that every design
/// point has its row. Returns the sweep and the rows.
pub fn load_complete(
    paths: &[std::path::PathBuf],
) -> Result<(Sweep, BTreeMap<usize, Vec<String>>), SweepError> {
    let (file, sources) = stream::merge(paths)?;
    let sweep = Sweep::from_config(&file.config, &paths[0])?;
    let design = sweep.design()?;
    check_design_values(&design, &file.rows, |i| &sources[i % sources.len()])?;
    let n = design.len();
    let missing: Vec<usize> = (0..n).filter(|i| !file.rows.contains_key(i)).collect();
    if let Some(&first) = missing.first() {
        return Err(SweepError::Incomplete {
            missing: missing.len(),
            total: n,
            first,
            files: unfinished(&missing, n, &sources),
        });
    }
    Ok((sweep, file.rows))
}

/// The files that lack rows, in shard order, each as `FILE (k of m rows missing)`:
/// design point i is in shard i mod N, the (i mod N)-th of `sources`.
fn unfinished(missing: &[usize], points: usize, sources: &[std::path::PathBuf]) -> String {
    let shards = sources.len().max(1);
    let mut lacking = vec![0usize; shards];
    for &i in missing {
        lacking[i % shards] += 1;
    }
    let in_shard = |s: usize| (points + shards - 1 - s) / shards;
    lacking
        .iter()
        .enumerate()
        .filter(|(_, &k)| k > 0)
        .map(|(s, k)| {
            let name = sources.get(s).map(|p| p.display().to_string());
            format!(
                "{} ({k} of {} rows missing)",
                name.unwrap_or_default(),
                in_shard(s)
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Writes the merged (or finished) rows as the final file of `sweep`, atomically.
pub fn write_final(
    sweep: &Sweep,
    rows: &BTreeMap<usize, Vec<String>>,
    out: &Path,
) -> Result<(), SweepError> {
    let header = stream::header(&sweep.config(), None, &sweep.columns());
    Ok(stream::finish(out, &header, rows)?)
}

/// The name of the indices file of the sweep file `out` (`stem-indices.csv`).
pub(crate) fn indices_path(out: &Path) -> std::path::PathBuf {
    let stem = out
        .file_stem()
        .map_or("sweep".into(), |s| s.to_string_lossy());
    out.with_file_name(format!("{stem}-indices.csv"))
}

/// Analyses complete rows and, except for a grid, writes the indices file beside
/// `out` ([`indices_path`]). Returns the indices and the file written.
pub fn write_indices(
    sweep: &Sweep,
    rows: &BTreeMap<usize, Vec<String>>,
    out: &Path,
) -> Result<(analysis::Indices, Option<std::path::PathBuf>), SweepError> {
    let indices = analysis::analyse(sweep, rows)?;
    if sweep.method == Method::Grid {
        return Ok((indices, None));
    }
    let path = indices_path(out);
    analysis::write(&path, &indices).map_err(|source| {
        SweepError::Stream(StreamError::Io {
            path: path.clone(),
            source,
        })
    })?;
    Ok((indices, Some(path)))
}

/// The outputs of complete rows as numbers: row `i` holds design point `i`'s output
/// columns (NaN where empty).
pub fn output_matrix(sweep: &Sweep, rows: &BTreeMap<usize, Vec<String>>) -> Array2<f64> {
    let k = sweep.factors.len();
    let columns = sweep.output_columns().len();
    let mut y = Array2::from_elem((rows.len(), columns), f64::NAN);
    for (mut out, r) in y.rows_mut().into_iter().zip(rows.values()) {
        for (j, cell) in out.iter_mut().enumerate() {
            *cell = r[1 + k + j].parse().unwrap_or(f64::NAN);
        }
    }
    y
}
