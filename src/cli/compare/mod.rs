//! `rtid compare`: the paper's Table 3 for two folders of experiment files.

use std::path::{Path, PathBuf};

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use rtid::experiments::compare::{self, Summary, THRESHOLD_ARCSEC};

mod speed_loop;

pub const LONG_ABOUT: &str = "\
Compares two rotary tables as the paper's Table 3 (§5, \"Comparison between driving \
mechanisms\"): one column per folder of experiment files, measured or written by \
`rtid experiment ... --out DIR`.

Every *.json in a folder whose top level has a `kind` is an experiment manifest and is \
evaluated as `rtid evaluate` would; other JSON (parameter files) is skipped. A manifest that \
cannot be read or evaluated is an error naming the file. A kind the folder lacks prints \
as \"—\". Rows, in the paper's order:
  frequency response    resonances, Hz: the 3 largest peaks of frequency_response.json \
(or a resonance file's peaks_hz)
  torsional stiffness   not measured by an experiment file (identified by fitting the \
model, docs/identification.md): always \"—\"
  friction torque       Coulomb friction at the motor, N·m, from torque_curve.json (half \
the torque jump at the velocity reversals)
  mean reversal B̄, repeatability R, accuracy A   ISO 230-2, arc-sec, from \
positioning.json (|B̄|, as the paper reports it)
  rotational fluctuation   from fluctuation.json: \"exists\" when the dominant order of the \
deviation θt − θm·Rg·Rw is larger than 0.72″, else \"cannot be identified\"
  unbalance mass        from unbalance.json: \"influences\" when the largest step of the \
deviation is larger than 0.72″, else \"no influence\"
  backlash              lost motion at the table, arc-sec: |B̄| of positioning.json, else \
the CW−CCW gap of fluctuation.json (the row says which)
  speed loop            where a folder holds a closed speed loop's response (a \
frequency response with response \"speed_loop\": `rtid import` of a drive's measuring \
function, or `rtid experiment speed-loop`): its −3 dB line with the phase there, and \
its peak below it; with --plot FILE.svg all of them on one Bode plot (a measurement as \
markers, a model as a line), and in --json as `speed_loop` of each folder

The threshold 0.72″ is two counts of the paper's table encoder (0.0001° = 0.36″): one \
count can be quantisation of a reading, more than two is a feature of the drive.

Examples:
  rtid experiment positioning --preset worm-gear --out runs/worm
  rtid experiment positioning --preset roller-gear-cam --out runs/roller
  rtid compare runs/worm runs/roller
  rtid compare runs/worm runs/roller --json
  rtid import freq_trace.XML --out measured
  rtid experiment speed-loop --params axis.json --tune tuned.json --out tuned
  rtid compare measured tuned --plot speed-loops.svg";

/// Arguments of `rtid compare`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder of the first table's experiment files.
    #[arg(value_name = "DIR_A")]
    pub a: PathBuf,
    /// Folder of the second table's experiment files.
    #[arg(value_name = "DIR_B")]
    pub b: PathBuf,
    /// Print JSON {"DIR_A": summary, "DIR_B": summary} instead of the table.
    #[arg(long)]
    pub json: bool,
    /// The folders' closed speed loops on one Bode plot (SVG; never over an input).
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// No progress display or notes on stderr (the command is quick: it has no
    /// progress bar; accepted like every command's `--quiet`, for scripts).
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let sa = compare::summarize(&a.a)?;
    let sb = compare::summarize(&a.b)?;
    let loops = [
        speed_loop::find(&sa.sources)?,
        speed_loop::find(&sb.sources)?,
    ];
    if let Some(path) = &a.plot {
        let inputs: Vec<&Path> = sa
            .sources
            .iter()
            .chain(&sb.sources)
            .map(PathBuf::as_path)
            .collect();
        let plot = crate::cli::common::plot::Plot::at(path.clone(), &inputs)?;
        speed_loop::plot(
            &plot,
            &[(&a.a, loops[0].as_ref()), (&a.b, loops[1].as_ref())],
        )?;
    }
    print(&a, &sa, &sb, &loops)
}

/// The table, or the JSON, with the speed loops' rows.
fn print(
    a: &Args,
    sa: &Summary,
    sb: &Summary,
    loops: &[Option<speed_loop::Found>; 2],
) -> anyhow::Result<()> {
    if a.json {
        let mut map = serde_json::Map::new();
        for (dir, s, l) in [(&a.a, sa, &loops[0]), (&a.b, sb, &loops[1])] {
            let mut v = rtid::io::json::value(s)?;
            if let (Some(l), serde_json::Value::Object(o)) = (l, &mut v) {
                o.insert("speed_loop".into(), rtid::io::json::value(&l.summary)?);
            }
            map.insert(dir.display().to_string(), v);
        }
        println!("{}", rtid::io::json::pretty(&map)?);
    } else {
        println!("Table 3. Comparison between driving mechanisms");
        let mut t = table(&[(&a.a, sa), (&a.b, sb)]);
        speed_loop::rows(&mut t, loops);
        println!("{t}");
    }
    Ok(())
}

/// The column header: folder name, and the mechanism if the manifests name one.
fn header(dir: &Path, s: &Summary) -> String {
    let name = dir
        .file_name()
        .map_or_else(|| dir.display().to_string(), |n| n.to_string_lossy().into());
    match &s.mechanism {
        Some(m) if *m != name => format!("{name} ({m})"),
        _ => name,
    }
}

const NONE: &str = "—";

fn num(v: Option<f64>, digits: usize) -> String {
    v.map_or(NONE.into(), |v| format!("{v:.digits$}"))
}

/// Table 3 for the given folders.
fn table(columns: &[(&PathBuf, &Summary)]) -> Table {
    type Row = (&'static str, fn(&Summary) -> String);
    let rows: [Row; 9] = [
        ("Frequency response (resonances), Hz", |s| {
            s.resonances_hz.as_ref().map_or(NONE.into(), |r| {
                if r.is_empty() {
                    "no peak".into()
                } else {
                    r.iter()
                        .map(|f| format!("{f:.0}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                }
            })
        }),
        ("Torsional stiffness, N·m/rad", |_| NONE.into()),
        ("Friction torque (motor), N·m", |s| {
            num(s.friction_torque_nm, 3)
        }),
        ("Mean reversal value B̄, ″", |s| num(s.b_mean_arcsec, 2)),
        ("Repeatability R, ″", |s| num(s.r_arcsec, 2)),
        ("Accuracy A, ″", |s| num(s.a_arcsec, 2)),
        ("Rotational fluctuation", |s| {
            s.fluctuation.as_ref().map_or(NONE.into(), |f| {
                let order = f
                    .dominant_order
                    .map_or(String::new(), |o| format!(" at {o:.0} c/rev"));
                let verdict = if f.present {
                    "exists"
                } else {
                    "cannot be identified"
                };
                format!("{verdict} ({:.2}″{order})", f.amplitude_arcsec)
            })
        }),
        ("Influence of unbalance mass", |s| {
            s.unbalance.as_ref().map_or(NONE.into(), |u| {
                let verdict = if u.influenced {
                    "influences"
                } else {
                    "no influence"
                };
                format!("{verdict} (step {:.2}″)", u.step_arcsec)
            })
        }),
        ("Backlash (lost motion), ″", |s| match s.backlash_arcsec {
            Some(b) => format!("{b:.2} (from {})", s.backlash_from.unwrap_or("?")),
            None => NONE.into(),
        }),
    ];
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    let mut head = vec![format!("Feature (threshold {THRESHOLD_ARCSEC:.2}″)")];
    head.extend(columns.iter().map(|(d, s)| header(d, s)));
    t.set_header(head);
    for (name, cell) in rows {
        let mut row = vec![name.to_string()];
        row.extend(columns.iter().map(|(_, s)| cell(s)));
        t.add_row(row);
    }
    t
}
