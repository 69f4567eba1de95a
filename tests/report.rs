//! `rtid report`: pages built from real runs of the binary in a temporary folder (an
//! identification, a positioning test, a sweep), their content, that they fetch
//! nothing, how bad input fails, and (slow tier) that a real browser renders them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use rtid::identify::IdentifyResult;
use rtid::report::html::sci;
use sha2::{Digest, Sha256};

/// Runs `rtid ARGS…` in `dir`.
fn rtid(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the rtid binary runs")
}

/// Runs `rtid ARGS…`, requires success and returns stdout.
fn rtid_ok(args: &[&str], dir: &Path) -> String {
    let out = rtid(args, dir);
    assert!(
        out.status.success(),
        "rtid {args:?} failed ({}): {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("stdout is UTF-8")
}

/// A failure: exit code 1, one line `error: …` naming every needle, no panic.
fn assert_error(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "exit status; stderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    assert_eq!(err.lines().count(), 1, "one line: {err:?}");
    for needle in needles {
        assert!(err.contains(needle), "`{needle}` not in: {err}");
    }
}

/// The runs every test reports on, made once in one temporary folder.
struct Runs {
    dir: tempfile::TempDir,
    /// The identification's input, as given to `rtid identify`.
    experiment: PathBuf,
    /// The positioning test's bidirectional accuracy A, arc-seconds.
    accuracy_arcsec: f64,
    /// `rtid sweep --json`'s output.
    sweep: serde_json::Value,
}

impl Runs {
    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn result(&self) -> IdentifyResult {
        let text = std::fs::read_to_string(self.path("fit.json")).unwrap();
        serde_json::from_str(&text).unwrap()
    }

    /// `rtid report ARGS… --out NAME` in the folder; returns the page.
    fn page(&self, args: &[&str], name: &str) -> String {
        let mut all = vec!["report"];
        all.extend(args);
        all.extend(["--out", name, "--quiet"]);
        rtid_ok(&all, self.dir.path());
        std::fs::read_to_string(self.path(name)).unwrap()
    }
}

/// The worm gear's virtual positioning test in `d`/pos, evaluated with a plot; its
/// bidirectional accuracy A, arc-seconds.
fn positioning_accuracy(d: &Path) -> f64 {
    rtid_ok(
        &[
            "experiment",
            "positioning",
            "--preset",
            "worm-gear",
            "--out",
            "pos",
        ],
        d,
    );
    let eval: serde_json::Value = serde_json::from_str(&rtid_ok(
        &[
            "evaluate",
            "pos/positioning.json",
            "--json",
            "--plot",
            "pos.svg",
        ],
        d,
    ))
    .unwrap();
    assert_eq!(eval["unit"], "arcsec");
    eval["axis"]["A"].as_f64().unwrap()
}

fn runs() -> &'static Runs {
    static RUNS: OnceLock<Runs> = OnceLock::new();
    RUNS.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let experiment = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fixtures/worm-gear/frequency_response.json");
        let exp = experiment.to_str().unwrap();
        rtid_ok(
            &[
                "identify",
                exp,
                "--preset",
                "worm-gear",
                "--set",
                "Kw=4.34e5",
                "--set",
                "Kg=1190",
                "--model",
                "linear",
                // Its resonances: residuals other than the gain curve's below (the
                // file has phase, whose default is its whole complex curve).
                "--objective",
                "resonance",
                "--out",
                "fit.json",
            ],
            d,
        );
        // Fits of the gain curve (79 residuals, linear: 0.05 s a fit): profiled and
        // resampled, and with Kg held (a nested fit to compare).
        let gain_curve = |extra: &[&str]| {
            let mut args = vec!["identify", exp, "--preset", "worm-gear", "--quiet"];
            args.extend(["--objective", "gain-curve", "--model", "linear"]);
            args.extend(extra);
            rtid_ok(&args, d);
        };
        // Kw and Kg: the file has phase, and the complex curve's default --fit would add
        // the dampings (Ciw's profile is open on this 10–600 Hz record).
        gain_curve(&[
            "--fit",
            "Kw,Kg",
            "--profile",
            "--resample",
            "5",
            "--out",
            "intervals.json",
        ]);
        gain_curve(&["--fit", "Kw", "--set", "Kg=800", "--out", "kw-only.json"]);
        let accuracy_arcsec = positioning_accuracy(d);
        let sweep = serde_json::from_str(&rtid_ok(
            &[
                "sweep",
                "--preset",
                "worm-gear",
                "--method",
                "local",
                "--vary",
                "Kw",
                "--vary",
                "Kg",
                "--outputs",
                "resonances",
                "--out",
                "s.csv",
                "--quiet",
                "--json",
            ],
            d,
        ))
        .unwrap();
        Runs {
            dir,
            experiment,
            accuracy_arcsec,
            sweep,
        }
    })
}

#[test]
fn an_identification_page_shows_the_fit_as_the_result_file_holds_it() {
    let r = runs();
    let page = r.page(&["fit.json"], "fit.html");
    let result = r.result();
    for (name, &value) in &result.parameters {
        assert!(page.contains(name.as_str()), "{name}");
        assert!(page.contains(&sci(value)), "{name} = {}", sci(value));
        assert!(page.contains(&sci(result.initial[name])), "start of {name}");
    }
    let sha = format!(
        "{:x}",
        Sha256::digest(std::fs::read(&r.experiment).unwrap())
    );
    assert!(page.contains(&sha), "the experiment's SHA-256");
    let provenance = result
        .provenance
        .as_ref()
        .expect("the command line records it");
    let command = shlex::split(&provenance.command).unwrap();
    assert_eq!(
        command[..3],
        ["rtid", "identify", r.experiment.to_str().unwrap()]
    );
    assert!(page.contains(&rtid::report::html::escape(&provenance.command)));
    assert_eq!(provenance.inputs.len(), 2, "the manifest and its data");
    for input in &provenance.inputs {
        let bytes = std::fs::read(&input.path).unwrap();
        assert_eq!(
            input.sha256,
            format!("{:x}", Sha256::digest(bytes)),
            "{}",
            input.path
        );
    }
    assert!(page.contains("same") && !page.contains("CHANGED"));
    assert!(
        page.contains("Fit against data"),
        "a chart of fit against data"
    );
    let gain = &result.comparisons[0];
    assert!(gain
        .curves
        .iter()
        .any(|c| c.label == "linear model, identified"));
    // The chart's title names the experiment's file, not its folder.
    let file = std::path::Path::new(&gain.source).file_name().unwrap();
    assert!(page.contains(&format!("identification: {}", file.to_string_lossy())));
    if gain.source.contains('/') {
        assert!(!page.contains(&format!("identification: {}", gain.source)));
    }
    assert!(page.contains(&result.mechanism));
    assert!(page.contains(&rtid::report::html::escape(
        &result.termination.0.to_string()
    )));
    assert!(page.contains(&format!("rtid {}", env!("CARGO_PKG_VERSION"))));
    assert!(page.contains("fitted by"), "the version that fitted it");
    assert!(page.contains("Correlations") && page.contains("class=\"heat\""));
    assert!(
        page.contains("residuals: "),
        "a residual chart per experiment"
    );
    assert!(page.contains("@page { size: A4"));
}

/// An input changed after the fit is flagged with its new hash; one gone is "not
/// found".
#[test]
fn an_identification_page_flags_an_input_changed_since_the_fit() {
    let r = runs();
    let dir = r.path("changed");
    std::fs::create_dir_all(&dir).unwrap();
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/worm-gear");
    for name in ["frequency_response.json", "frequency_response.csv"] {
        std::fs::copy(fixtures.join(name), dir.join(name)).unwrap();
    }
    let args = [
        "--preset",
        "worm-gear",
        "--model",
        "linear",
        "--quiet",
        "--out",
    ];
    let mut run = vec!["identify", "frequency_response.json"];
    run.extend(args);
    run.push("fit.json");
    rtid_ok(&run, &dir);
    let mut csv = std::fs::read_to_string(dir.join("frequency_response.csv")).unwrap();
    csv.push('\n');
    std::fs::write(dir.join("frequency_response.csv"), &csv).unwrap();
    rtid_ok(&["report", "fit.json", "--out", "r.html", "--quiet"], &dir);
    let page = std::fs::read_to_string(dir.join("r.html")).unwrap();
    let now = format!("{:x}", Sha256::digest(csv.as_bytes()));
    assert!(
        page.contains(&format!("CHANGED since the fit: {now}")),
        "the CSV"
    );
    assert_eq!(
        page.matches("CHANGED").count(),
        1,
        "the manifest is the same"
    );
    std::fs::remove_file(dir.join("frequency_response.json")).unwrap();
    rtid_ok(&["report", "fit.json", "--out", "r.html", "--quiet"], &dir);
    let page = std::fs::read_to_string(dir.join("r.html")).unwrap();
    assert!(page.contains("not found"));
}

#[test]
fn an_identification_page_shows_the_profile_and_bootstrap_intervals() {
    let r = runs();
    let page = r.page(&["intervals.json"], "intervals.html");
    let text = std::fs::read_to_string(r.path("intervals.json")).unwrap();
    let result: IdentifyResult = serde_json::from_str(&text).unwrap();
    let profiles = result.profiles.as_ref().unwrap();
    let resampling = result.resampling.as_ref().unwrap();
    for name in result.parameters.keys() {
        let p = &profiles[name];
        for end in [p.lower, p.upper] {
            assert!(page.contains(&sci(end.unwrap())), "{name}: profile end");
        }
        let i = resampling.intervals[name];
        for end in [i.lower, i.upper] {
            assert!(page.contains(&sci(end)), "{name}: bootstrap {end}");
        }
        for spread in [i.standard_error, i.bias] {
            assert!(page.contains(&format!("{spread:.3e}")), "{name}: {spread}");
        }
        assert!(
            page.contains(&format!("profile likelihood of {name}")),
            "{name}: chart"
        );
    }
}

#[test]
fn identifications_of_the_same_data_are_compared_and_others_are_not() {
    let r = runs();
    let page = r.page(&["intervals.json", "kw-only.json"], "selection.html");
    assert!(page.contains("Model selection"));
    let out = rtid_ok(
        &["select", "intervals.json", "kw-only.json", "--json"],
        r.dir.path(),
    );
    let s: serde_json::Value = serde_json::from_str(&out).unwrap();
    for c in s["candidates"].as_array().unwrap() {
        let aic = format!("{:.2}", c["aic"].as_f64().unwrap());
        assert!(page.contains(&aic), "AIC {aic}");
    }
    assert!(page.contains("F-test: intervals.json adds Kg to kw-only.json"));
    let page = r.page(&["fit.json", "intervals.json"], "other-data.html");
    assert!(page.contains("are not compared") && page.contains("fits other residuals"));
}

/// A result that records no provenance (written by a library caller, or by an
/// older rtid) gets today's hashes of its experiments, a missing one "not found".
#[test]
fn an_experiment_that_is_gone_is_not_found_rather_than_an_error() {
    let r = runs();
    let mut fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(r.path("fit.json")).unwrap()).unwrap();
    fit["experiments"] = serde_json::json!(["gone/frequency_response.json"]);
    fit.as_object_mut().unwrap().remove("provenance").unwrap();
    std::fs::write(r.path("moved-fit.json"), fit.to_string()).unwrap();
    let page = r.page(&["moved-fit.json"], "moved.html");
    assert!(page.contains("gone/frequency_response.json") && page.contains("not found"));
    assert!(page.contains("does not record its inputs"));
}

#[test]
fn the_positioning_verdict_follows_the_tolerance() {
    let r = runs();
    let a = r.accuracy_arcsec;
    assert!(a > 0.0);
    let above = format!("{}", (a * 1.5).ceil());
    let below = format!("{:.3}", a * 0.5);
    let pass = r.page(
        &["pos/positioning.json", "--tolerance-arcsec", &above],
        "pass.html",
    );
    assert!(pass.contains(">PASS<") && !pass.contains(">FAIL<"));
    assert!(
        pass.contains(&format!("A = {a:.2} ″")),
        "A as the page prints it"
    );
    let fail = r.page(
        &["pos/positioning.json", "--tolerance-arcsec", &below],
        "fail.html",
    );
    assert!(fail.contains(">FAIL<") && !fail.contains(">PASS<"));
    let none = r.page(&["pos/positioning.json"], "none.html");
    assert!(none.contains("no tolerance given") && !none.contains(">PASS<"));
    for figure in ["R↑", "R↓", "E↑", "E↓", "A↑", "A↓", "x̄↑", "Bi", "Ri"] {
        assert!(none.contains(figure), "{figure}");
    }
}

#[test]
fn a_sweep_page_shows_the_library_s_indices_and_tornadoes() {
    let r = runs();
    let page = r.page(&["s.csv"], "sweep.html");
    assert!(page.contains("local") && page.contains("Kw") && page.contains("Kg"));
    let rows = r.sweep["indices"]["rows"].as_array().unwrap();
    assert!(!rows.is_empty());
    for row in rows {
        let v = row["values"][0].as_f64().unwrap();
        assert!(page.contains(&format!("{v:.4}")), "{row}");
    }
    assert!(page.contains("<svg"), "tornado charts inline");
}

#[test]
fn several_files_make_one_page_with_a_table_of_contents() {
    let r = runs();
    let out = rtid_ok(
        &[
            "report",
            "fit.json",
            "pos/positioning.json",
            "s.csv",
            "--tolerance-arcsec",
            "1000",
            "--title",
            "Acceptance <B&R>",
            "--out",
            "all.html",
            "--json",
        ],
        r.dir.path(),
    );
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(json["out"], "all.html");
    let kinds: Vec<&str> = json["sections"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["identification", "positioning", "sweep"]);
    let page = std::fs::read_to_string(r.path("all.html")).unwrap();
    for i in 1..=3 {
        assert!(page.contains(&format!("href=\"#section-{i}\"")), "link {i}");
        assert!(page.contains(&format!("id=\"section-{i}\"")), "anchor {i}");
    }
    assert!(page.contains("Acceptance &lt;B&amp;R&gt;") && !page.contains("<B&R>"));
    let plain = rtid_ok(&["report", "s.csv", "--out", "plain.html"], r.dir.path());
    assert_eq!(plain.trim(), "wrote plain.html");
}

#[test]
fn a_page_fetches_nothing_from_the_network() {
    let r = runs();
    let page = r.page(
        &["fit.json", "pos/positioning.json", "s.csv"],
        "offline.html",
    );
    assert!(!page.contains("http://") && !page.contains("https://"));
    assert!(!page.contains("src=") && !page.contains("@import") && !page.contains("url("));
    for (i, _) in page.match_indices("href=") {
        assert!(page[i..].starts_with("href=\"#"), "{}", &page[i..i + 40]);
    }
}

#[test]
fn bad_input_is_one_clear_error_naming_the_file_or_option() {
    let r = runs();
    let d = r.dir.path();
    std::fs::write(d.join("random.json"), r#"{"colour": "green", "size": 3}"#).unwrap();
    let out = rtid(&["report", "random.json", "--out", "x.html"], d);
    assert_error(&out, &["random.json", "expected an identification result"]);
    let out = rtid(&["report", "missing.json", "--out", "x.html"], d);
    assert_error(&out, &["missing.json"]);
    std::fs::write(d.join("broken.json"), "{\"parameters\": ").unwrap();
    let out = rtid(&["report", "broken.json", "--out", "x.html"], d);
    assert_error(&out, &["broken.json", "not JSON"]);
    let out = rtid(&["report", "fit.json", "s.csv", "--out", "s.csv"], d);
    assert_error(&out, &["--out", "s.csv", "input"]);
    let out = rtid(
        &[
            "report",
            "pos/positioning.json",
            "--tolerance-um",
            "5",
            "--out",
            "x.html",
        ],
        d,
    );
    assert_error(
        &out,
        &[
            "--tolerance-um",
            "positioning.json",
            "--tolerance-arcsec",
            "rotary",
        ],
    );
    let out = rtid(
        &[
            "report",
            "pos/positioning.json",
            "--tolerance-arcsec",
            "-2",
            "--out",
            "x.html",
        ],
        d,
    );
    assert_error(&out, &["--tolerance-arcsec"]);
    let out = rtid(&["report", "pos", "--out", "x.html"], d);
    assert_error(&out, &["pos", "not a regular file"]);
    let sweep = std::fs::read_to_string(d.join("s.csv")).unwrap();
    let head: Vec<&str> = sweep.lines().take(4).collect();
    std::fs::write(d.join("part.csv"), head.join("\n") + "\n").unwrap();
    let out = rtid(&["report", "part.csv", "--out", "x.html"], d);
    assert_error(&out, &["part.csv", "sweep file"]);
    assert!(!d.join("x.html").exists(), "no page after an error");
}

#[test]
fn an_experiment_of_another_kind_is_named_as_such() {
    let experiment =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/worm-gear/frequency_response.json");
    let dir = tempfile::tempdir().unwrap();
    let out = rtid(
        &["report", experiment.to_str().unwrap(), "--out", "x.html"],
        dir.path(),
    );
    assert_error(
        &out,
        &[
            "frequency_response.json",
            "frequency_response",
            "positioning",
        ],
    );
}

/// The chromium binary on PATH; the browser test fails without it.
fn chromium() -> PathBuf {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .map(|d| d.join("chromium"))
        .find(|p| p.is_file())
        .expect("the browser test needs `chromium` on PATH (.ci/run installs it: apt-get install chromium)")
}

#[test]
#[cfg_attr(not(feature = "slow-tests"), ignore = "slow tier: needs chromium")]
fn chromium_renders_the_page_without_console_errors() {
    let browser = chromium();
    let r = runs();
    r.page(
        &["fit.json", "pos/positioning.json", "s.csv"],
        "browser.html",
    );
    let url = format!("file://{}", r.path("browser.html").display());
    let shot = r.path("shot.png");
    let base = ["--headless", "--no-sandbox", "--disable-gpu"];
    let out = Command::new(&browser)
        .args(base)
        .args(["--enable-logging=stderr", "--v=0"])
        .arg(format!("--screenshot={}", shot.display()))
        .args(["--window-size=1240,1754", &url])
        .output()
        .expect("chromium runs");
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "chromium failed: {log}");
    let size = std::fs::metadata(&shot).map(|m| m.len()).unwrap_or(0);
    assert!(size > 20_000, "screenshot of {size} bytes: {log}");
    // A console.error, a failed load or an exception is logged as `INFO:CONSOLE…`
    // (the page has no script, so any console line is a fault).
    let console: Vec<&str> = log
        .lines()
        .filter(|l| l.contains(":CONSOLE") || l.contains("Uncaught"))
        .collect();
    assert!(console.is_empty(), "console messages: {console:#?}");
    let dom = Command::new(&browser)
        .args(base)
        .args(["--dump-dom", &url])
        .output()
        .expect("chromium runs");
    assert!(dom.status.success());
    let dom = String::from_utf8_lossy(&dom.stdout);
    for value in r.result().parameters.values() {
        assert!(
            dom.contains(&sci(*value)),
            "{} in the rendered DOM",
            sci(*value)
        );
    }
    assert!(dom.contains("id=\"section-3\""));
}
