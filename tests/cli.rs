//! The real `rtid` binary, run in temporary folders: what each command prints and
//! writes, and how it fails.

use std::path::Path;
use std::process::Output;

use support::*;

/// Running the binary and reading what it leaves behind.
mod support {
    use std::path::Path;
    use std::process::{Command, Output};

    /// Runs `rtid ARGS…` with `dir` as the working directory.
    pub fn rtid(args: &[&str], dir: &Path) -> Output {
        Command::new(env!("CARGO_BIN_EXE_rtid"))
            .args(args)
            .current_dir(dir)
            .output()
            .expect("the rtid binary runs")
    }

    pub fn stdout(out: &Output) -> String {
        String::from_utf8(out.stdout.clone()).expect("stdout is UTF-8")
    }

    pub fn stderr(out: &Output) -> String {
        String::from_utf8(out.stderr.clone()).expect("stderr is UTF-8")
    }

    /// Starts `rtid ARGS…` in `dir`, sends it SIGINT (Ctrl-C) after `delay_ms` and
    /// waits for it to end.
    pub fn interrupted<S: AsRef<std::ffi::OsStr>>(args: &[S], dir: &Path, delay_ms: u64) -> Output {
        use std::process::Stdio;
        let child = Command::new(env!("CARGO_BIN_EXE_rtid"))
            .args(args)
            .current_dir(dir)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the rtid binary runs");
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        // SAFETY: a signal to the child this test started and still owns.
        unsafe {
            libc::kill(child.id() as i32, libc::SIGINT);
        }
        child.wait_with_output().expect("rtid ends")
    }

    /// Runs `rtid ARGS…`, requires exit code 0 and returns stdout.
    pub fn rtid_ok(args: &[&str], dir: &Path) -> String {
        let out = rtid(args, dir);
        assert!(
            out.status.success(),
            "rtid {args:?} failed ({}): {}",
            out.status,
            stderr(&out)
        );
        stdout(&out)
    }

    /// Runs `rtid ARGS…` and parses its stdout as JSON.
    pub fn rtid_json(args: &[&str], dir: &Path) -> serde_json::Value {
        let text = rtid_ok(args, dir);
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("rtid {args:?}: {e}\n{text}"))
    }

    /// A failure reported by `main`: exit code 1, one line `error: …` on stderr naming
    /// every one of `needles`, no panic. Returns that line.
    pub fn assert_one_line_error(out: &Output, needles: &[&str]) -> String {
        let err = stderr(out);
        assert_eq!(out.status.code(), Some(1), "exit status; stderr: {err}");
        assert!(!err.contains("panicked"), "panic: {err}");
        let lines: Vec<&str> = err.lines().collect();
        assert_eq!(lines.len(), 1, "stderr is one line: {err:?}");
        assert!(lines[0].starts_with("error: "), "{err}");
        for needle in needles {
            assert!(lines[0].contains(needle), "`{needle}` not in: {err}");
        }
        lines[0].to_string()
    }

    /// A CSV of numbers: the header and every row parsed as finite `f64`.
    pub struct Table {
        pub header: Vec<String>,
        pub rows: Vec<Vec<f64>>,
    }

    impl Table {
        pub fn read(path: &Path) -> Table {
            let mut reader =
                csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let header = reader
                .headers()
                .unwrap()
                .iter()
                .map(String::from)
                .collect::<Vec<_>>();
            let mut rows = Vec::new();
            for (i, record) in reader.records().enumerate() {
                let record = record.unwrap();
                assert_eq!(record.len(), header.len(), "row {i}: {record:?}");
                let row: Vec<f64> = record
                    .iter()
                    .map(|cell| {
                        let v: f64 = cell
                            .parse()
                            .unwrap_or_else(|_| panic!("row {i}: `{cell}` is not a number"));
                        assert!(v.is_finite(), "row {i}: `{cell}` is not finite");
                        v
                    })
                    .collect();
                rows.push(row);
            }
            Table { header, rows }
        }

        /// The index of column `name`.
        pub fn col(&self, name: &str) -> usize {
            self.header
                .iter()
                .position(|h| h == name)
                .unwrap_or_else(|| panic!("no column `{name}` in {:?}", self.header))
        }

        /// Every value of column `name`.
        pub fn column(&self, name: &str) -> Vec<f64> {
            let i = self.col(name);
            self.rows.iter().map(|r| r[i]).collect()
        }

        /// The last value of column `name`.
        pub fn last(&self, name: &str) -> f64 {
            *self.column(name).last().expect("at least one row")
        }
    }

    /// The numbers of a JSON array.
    pub fn numbers(v: &serde_json::Value, key: &str) -> Vec<f64> {
        v[key]
            .as_array()
            .unwrap_or_else(|| panic!("`{key}` is not an array: {v}"))
            .iter()
            .map(|x| {
                x.as_f64()
                    .unwrap_or_else(|| panic!("{key}: {x} not a number"))
            })
            .collect()
    }

    /// `actual` and `expected` have the same length and agree within `tol`.
    pub fn assert_close(actual: &[f64], expected: &[f64], tol: f64, what: &str) {
        assert_eq!(actual.len(), expected.len(), "{what}: {actual:?}");
        for (a, e) in actual.iter().zip(expected) {
            assert!((a - e).abs() <= tol, "{what}: {actual:?} vs {expected:?}");
        }
    }
}

const ARCSEC: f64 = std::f64::consts::PI / 180.0 / 3600.0;

const STATE_HEADER: [&str; 10] = [
    "time_s",
    "motor_torque_nm",
    "motor_angle_rad",
    "motor_velocity_rad_per_s",
    "shaft_angle_rad",
    "shaft_velocity_rad_per_s",
    "axial_displacement_m",
    "axial_velocity_m_per_s",
    "table_angle_rad",
    "table_velocity_rad_per_s",
];

fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// `rtid simulate --preset worm-gear ARGS…` in `dir`.
fn simulate_worm(args: &[&str], dir: &Path) -> Output {
    let mut all = vec!["simulate", "--preset", "worm-gear"];
    all.extend(args);
    rtid(&all, dir)
}

mod modes {
    use super::*;

    fn modes_json(preset: &str) -> serde_json::Value {
        rtid_json(&["modes", "--preset", preset, "--json"], tempdir().path())
    }

    #[test]
    fn worm_gear_frequencies_ascend_and_match_the_linear_model() {
        let m = modes_json("worm-gear");
        let clamped = numbers(&m, "clamped_hz");
        let free = numbers(&m, "free_hz");
        for hz in [&clamped, &free] {
            assert!(hz.windows(2).all(|w| w[0] < w[1]), "ascending: {hz:?}");
        }
        assert_close(&clamped, &[186.5, 236.9, 1510.7], 0.1, "clamped_hz");
        assert_close(&free, &[192.0, 253.0, 1510.7], 0.1, "free_hz");
        assert!(
            free.iter().all(|&f| f > 1.0),
            "rigid-body mode listed: {free:?}"
        );
    }

    #[test]
    fn roller_gear_cam_clamped_frequencies() {
        let m = modes_json("roller-gear-cam");
        assert_close(
            &numbers(&m, "clamped_hz"),
            &[166.9, 932.0],
            0.1,
            "clamped_hz",
        );
    }

    #[test]
    fn table_output_names_the_motor_held_modes() {
        let text = rtid_ok(&["modes", "--preset", "worm-gear"], tempdir().path());
        assert!(text.contains("motor held"), "{text}");
        assert!(text.contains("186.5"), "{text}");
    }
}

mod simulate {
    use super::*;

    #[test]
    fn sine_writes_every_state_at_the_sample_period() {
        let dir = tempdir();
        let out = simulate_worm(
            &[
                "--input",
                "sine:freq_hz=100,amp_nm=5",
                "--duration-s",
                "0.05",
                "--out",
                "run.csv",
            ],
            dir.path(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let csv = Table::read(&dir.path().join("run.csv"));
        assert_eq!(csv.header, STATE_HEADER);
        assert_eq!(csv.rows.len(), 501, "0.05 s every 1e-4 s, with t = 0");
        let time = csv.column("time_s");
        assert_eq!(time[0], 0.0);
        assert!((time[500] - 0.05).abs() < 1e-9, "last t = {}", time[500]);
        assert!(time.windows(2).all(|w| w[1] > w[0]), "time increases");
        let torque = csv.column("motor_torque_nm");
        for i in [0, 1, 7, 25, 123, 250, 401, 500] {
            let expected = 5.0 * (2.0 * std::f64::consts::PI * 100.0 * time[i]).sin();
            assert!(
                (torque[i] - expected).abs() < 1e-6,
                "t = {}: {} vs {expected}",
                time[i],
                torque[i]
            );
        }
    }

    #[test]
    fn json_summary_reports_steps_and_step_size() {
        let dir = tempdir();
        let summary = rtid_json(
            &[
                "simulate",
                "--preset",
                "worm-gear",
                "--input",
                "sine:freq_hz=100,amp_nm=5",
                "--duration-s",
                "0.05",
                "--out",
                "run.csv",
                "--json",
            ],
            dir.path(),
        );
        assert_eq!(summary["steps"].as_f64(), Some(5000.0), "{summary}");
        assert_eq!(summary["dt_s"].as_f64(), Some(1e-5), "{summary}");
        assert!(dir.path().join("run.csv").is_file());
    }

    fn move_to_10_degrees(input: &str) {
        let dir = tempdir();
        let out = simulate_worm(
            &["--input", input, "--duration-s", "0.6", "--out", "move.csv"],
            dir.path(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let csv = Table::read(&dir.path().join("move.csv"));
        let mut header = STATE_HEADER.to_vec();
        header.push("reference_rad");
        assert_eq!(csv.header, header);
        let target = 10f64.to_radians();
        assert!((csv.last("reference_rad") - target).abs() < 1e-12);
        let error = (csv.last("table_angle_rad") - target) / ARCSEC;
        assert!(
            error.abs() < 40.0,
            "{input}: final error {error:.1} arc-sec"
        );
    }

    #[test]
    fn semi_closed_move_reaches_10_degrees() {
        move_to_10_degrees("move:target_deg=10");
    }

    #[test]
    fn full_closed_move_reaches_10_degrees() {
        move_to_10_degrees("move:target_deg=10,loop=full_closed");
    }

    #[test]
    fn step_torque_switches_on_at_its_time_and_turns_the_table() {
        let dir = tempdir();
        let out = simulate_worm(
            &[
                "--input",
                "step:torque_nm=1,at_s=0.01",
                "--duration-s",
                "0.03",
                "--out",
                "step.csv",
            ],
            dir.path(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let csv = Table::read(&dir.path().join("step.csv"));
        assert_eq!(csv.rows.len(), 301);
        for (t, q) in csv
            .column("time_s")
            .iter()
            .zip(csv.column("motor_torque_nm"))
        {
            if *t < 0.0099 {
                assert_eq!(q, 0.0, "t = {t}");
            } else if *t > 0.0101 {
                assert_eq!(q, 1.0, "t = {t}");
            }
        }
        assert!(csv.last("motor_angle_rad") > 0.0);
        assert!(csv.last("table_angle_rad") > 0.0);
    }

    #[test]
    fn torque_file_is_interpolated_and_held() {
        let dir = tempdir();
        std::fs::write(
            dir.path().join("torque.csv"),
            "time_s,motor_torque_nm\n0,0\n0.01,2\n0.02,2\n",
        )
        .unwrap();
        let out = simulate_worm(
            &[
                "--input",
                "file:torque.csv",
                "--duration-s",
                "0.03",
                "--out",
                "file.csv",
            ],
            dir.path(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let csv = Table::read(&dir.path().join("file.csv"));
        assert_eq!(csv.rows.len(), 301);
        let (time, torque) = (csv.column("time_s"), csv.column("motor_torque_nm"));
        for i in [0, 25, 50, 150, 250, 300] {
            let expected = (time[i] / 0.01).min(1.0) * 2.0;
            assert!(
                (torque[i] - expected).abs() < 1e-9,
                "t = {}: {} vs {expected}",
                time[i],
                torque[i]
            );
        }
    }

    #[test]
    fn torque_file_with_a_bad_cell_names_file_and_line() {
        let dir = tempdir();
        std::fs::write(
            dir.path().join("torque.csv"),
            "time_s,motor_torque_nm\n0,0\n0.01,abc\n",
        )
        .unwrap();
        let out = simulate_worm(
            &[
                "--input",
                "file:torque.csv",
                "--duration-s",
                "0.03",
                "--out",
                "file.csv",
            ],
            dir.path(),
        );
        assert_one_line_error(&out, &["torque.csv", "line 3", "abc"]);
        assert!(!dir.path().join("file.csv").exists());
    }
}

mod params {
    use super::*;

    #[test]
    fn a_saved_override_feeds_modes_and_reads_back() {
        let dir = tempdir();
        let out = rtid(
            &[
                "params",
                "--preset",
                "worm-gear",
                "--set",
                "Kw=5e5",
                "--out",
                "p.json",
            ],
            dir.path(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(dir.path().join("p.json").is_file());

        let preset = numbers(
            &rtid_json(&["modes", "--preset", "worm-gear", "--json"], dir.path()),
            "clamped_hz",
        )[0];
        let stiffer = numbers(
            &rtid_json(&["modes", "--params", "p.json", "--json"], dir.path()),
            "clamped_hz",
        )[0];
        assert!((preset - 186.5).abs() < 0.1, "{preset}");
        assert!(stiffer > preset + 1.0, "{stiffer} vs {preset}");

        let text = rtid_ok(&["params", "--params", "p.json", "--json"], dir.path());
        assert!(text.contains("\"Kw\": 500000.0"), "{text}");
    }
}

mod errors {
    use super::*;

    fn modes(args: &[&str]) -> Output {
        let mut all = vec!["modes"];
        all.extend(args);
        rtid(&all, tempdir().path())
    }

    /// The worm-gear preset as a parameter file in `dir`, changed by `edit`.
    fn params_file(dir: &Path, name: &str, edit: impl FnOnce(&mut serde_json::Value)) {
        let mut p = rtid_json(&["params", "--preset", "worm-gear", "--json"], dir);
        edit(&mut p);
        std::fs::write(dir.join(name), serde_json::to_string_pretty(&p).unwrap()).unwrap();
    }

    #[test]
    fn unknown_preset_lists_the_known_ones() {
        assert_one_line_error(&modes(&["--preset", "worm"]), &["worm-gear"]);
    }

    #[test]
    fn negative_stiffness_names_the_parameter() {
        assert_one_line_error(
            &modes(&["--preset", "worm-gear", "--set", "Kw=-1"]),
            &["Kw"],
        );
    }

    #[test]
    fn spur_gear_stiffness_does_not_apply_to_the_roller_cam() {
        assert_one_line_error(
            &modes(&["--preset", "roller-gear-cam", "--set", "Kg=1"]),
            &["Kg", "does not apply"],
        );
    }

    #[test]
    fn params_file_syntax_error_names_file_and_line() {
        let dir = tempdir();
        std::fs::write(
            dir.path().join("broken.json"),
            "{\n  \"name\": \"x\",\n  \"Jm\": ,\n}\n",
        )
        .unwrap();
        let out = rtid(&["modes", "--params", "broken.json"], dir.path());
        assert_one_line_error(&out, &["broken.json", "line 3"]);
    }

    #[test]
    fn params_file_with_zero_table_inertia_names_it() {
        let dir = tempdir();
        params_file(dir.path(), "zero-jt.json", |p| p["Jt"] = 0.0.into());
        let out = rtid(&["modes", "--params", "zero-jt.json"], dir.path());
        assert_one_line_error(&out, &["zero-jt.json", "Jt"]);
    }

    #[test]
    fn a_mechanism_is_required() {
        assert_one_line_error(&modes(&[]), &["--preset", "--params"]);
    }

    #[test]
    fn sine_without_amplitude_is_rejected_by_the_parser() {
        let out = simulate_worm(
            &[
                "--input",
                "sine:freq_hz=1",
                "--duration-s",
                "0.01",
                "--out",
                "x.csv",
            ],
            tempdir().path(),
        );
        let err = stderr(&out);
        assert!(!out.status.success());
        assert!(err.contains("amp_nm"), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }

    /// A sine the integration step cannot resolve and a control period longer than
    /// the drive's slowest mode are refused (issue 59), naming what is wrong.
    #[test]
    fn inputs_the_model_cannot_resolve_are_refused() {
        let dir = tempdir();
        let out = simulate_worm(
            &[
                "--input",
                "sine:freq_hz=1e9,amp_nm=5",
                "--duration-s",
                "0.01",
                "--out",
                "x.csv",
            ],
            dir.path(),
        );
        assert_one_line_error(&out, &["a sine of 1e9 Hz", "Nyquist frequency 50000 Hz"]);
        let out = simulate_worm(
            &[
                "--set",
                "Tc=10",
                "--input",
                "move:target_deg=1",
                "--duration-s",
                "0.01",
                "--out",
                "x.csv",
            ],
            dir.path(),
        );
        assert_one_line_error(&out, &["control period Tc = 10 s", "slowest mode"]);
        assert!(!dir.path().join("x.csv").exists());
    }

    #[test]
    fn negative_duration_is_rejected() {
        let dir = tempdir();
        let out = simulate_worm(
            &[
                "--input",
                "sine:freq_hz=100,amp_nm=5",
                "--duration-s",
                "-1",
                "--out",
                "x.csv",
            ],
            dir.path(),
        );
        assert_one_line_error(&out, &["--duration-s"]);
        assert!(!dir.path().join("x.csv").exists());
    }

    #[test]
    fn negative_duration_after_an_equals_sign_is_rejected() {
        let dir = tempdir();
        let out = simulate_worm(
            &[
                "--input",
                "sine:freq_hz=100,amp_nm=5",
                "--duration-s=-1",
                "--out",
                "x.csv",
            ],
            dir.path(),
        );
        assert_one_line_error(&out, &["--duration-s -1", "positive"]);
        assert!(!dir.path().join("x.csv").exists());
    }

    #[test]
    fn too_large_a_step_is_rejected() {
        let dir = tempdir();
        let out = simulate_worm(
            &[
                "--input",
                "sine:freq_hz=100,amp_nm=5",
                "--duration-s",
                "0.01",
                "--dt-s",
                "1e-2",
                "--out",
                "x.csv",
            ],
            dir.path(),
        );
        assert_one_line_error(&out, &["too large"]);
        assert!(!dir.path().join("x.csv").exists());
    }
}

mod atomic_output {
    use super::*;

    const OLD: &str = "an earlier run\n";

    /// Runs a failing `simulate` over an existing `run.csv`; it must be left as it was,
    /// with no temporary file beside it.
    fn failing_run_keeps_old_output(args: &[&str]) -> String {
        let dir = tempdir();
        let path = dir.path().join("run.csv");
        std::fs::write(&path, OLD).unwrap();
        let mut all = args.to_vec();
        all.extend(["--out", "run.csv"]);
        let out = simulate_worm(&all, dir.path());
        let line = assert_one_line_error(&out, &[]);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), OLD);
        let files: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(files, ["run.csv"]);
        line
    }

    #[test]
    fn a_rejected_step_leaves_the_previous_output() {
        let line = failing_run_keeps_old_output(&[
            "--input",
            "sine:freq_hz=100,amp_nm=5",
            "--duration-s",
            "0.01",
            "--dt-s",
            "1e-2",
        ]);
        assert!(line.contains("too large"), "{line}");
    }

    /// A control period that is not a whole number of steps fails inside the
    /// simulation, after the CSV header has been written to the temporary file.
    #[test]
    fn a_failure_mid_write_leaves_the_previous_output() {
        let line = failing_run_keeps_old_output(&[
            "--input",
            "move:target_deg=10",
            "--duration-s",
            "0.01",
            "--dt-s",
            "3e-6",
        ]);
        assert!(line.contains("run.csv"), "{line}");
    }
}

mod help {
    use super::*;

    #[test]
    fn top_level_help_names_the_presets() {
        let text = rtid_ok(&["--help"], tempdir().path());
        assert!(text.contains("worm-gear"), "{text}");
        assert!(text.contains("roller-gear-cam"), "{text}");
    }

    #[test]
    fn simulate_help_lists_the_inputs() {
        let text = rtid_ok(&["simulate", "--help"], tempdir().path());
        for input in ["sine:", "step:", "file:", "move:"] {
            assert!(text.contains(input), "{input}: {text}");
        }
    }
}

mod experiments {
    use super::*;

    #[test]
    fn a_virtual_positioning_test_evaluates_to_the_same_statistics() {
        let dir = tempdir();
        let out = rtid(
            &[
                "experiment",
                "positioning",
                "--preset",
                "roller-gear-cam",
                "--runs",
                "2",
                "--target-step-deg",
                "180",
                "--out",
                "pos",
                "--json",
            ],
            dir.path(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let made: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        for f in ["positioning.json", "positioning.csv", "positioning.svg"] {
            assert!(dir.path().join("pos").join(f).exists(), "{f}");
        }
        let again = rtid(&["evaluate", "pos/positioning.json", "--json"], dir.path());
        assert!(again.status.success(), "{}", stderr(&again));
        let read: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
        assert_eq!(made["axis"], read["axis"]);
        for key in [
            "B", "B_mean", "R_up", "R_down", "R", "E_up", "E_down", "E", "M", "A_up", "A_down", "A",
        ] {
            assert!(read["axis"][key].is_number(), "{key}");
        }
    }

    #[test]
    fn a_linear_frequency_response_finds_the_motor_held_modes() {
        let dir = tempdir();
        let out = rtid(
            &[
                "experiment",
                "frequency-response",
                "--preset",
                "worm-gear",
                "--linear",
                "--out",
                "fr",
                "--json",
            ],
            dir.path(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let peaks: Vec<f64> = v["peaks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["frequency_hz"].as_f64().unwrap())
            .collect();
        // The damped peaks of the table/motor ratio sit near the motor-held modes
        // (186.5 and 236.9 Hz), shifted by the damping.
        assert_eq!(peaks.len(), 2, "{peaks:?}");
        assert!(
            (peaks[0] - 186.5).abs() < 3.0 && (peaks[1] - 236.9).abs() < 5.0,
            "{peaks:?}"
        );
        assert!(dir.path().join("fr/frequency_response.svg").exists());
    }

    #[test]
    fn evaluating_a_malformed_experiment_names_file_and_line() {
        let dir = tempdir();
        std::fs::write(
            dir.path().join("fr.json"),
            r#"{"kind": "frequency_response", "data": "fr.csv"}"#,
        )
        .unwrap();
        std::fs::write(
            dir.path().join("fr.csv"),
            "frequency_hz,gain_db\n10,0.1\n20,abc\n",
        )
        .unwrap();
        let out = rtid(&["evaluate", "fr.json"], dir.path());
        assert_one_line_error(&out, &["fr.csv", "line 3", "gain_db"]);
    }

    /// The raw-data test on the roller gear cam (no backlash): the record, the gain and
    /// coherence plots, the resonance near the motor-held 167 Hz mode, and the same
    /// estimate from `rtid evaluate` with a coarser segment; a dropped sample is an
    /// error naming the line.
    #[test]
    fn a_recorded_frequency_response_evaluates_to_its_resonance() {
        let dir = tempdir();
        let args = [
            "experiment",
            "frequency-response-time",
            "--preset",
            "roller-gear-cam",
            "--duration-s",
            "8",
            "--quiet",
            "--out",
            "raw",
            "--json",
        ];
        let v = rtid_json(&args, dir.path());
        assert_eq!(v["estimator"], "h1");
        assert_eq!(v["segments"], 7);
        let peaks = v["peaks"].as_array().unwrap();
        let top = peaks
            .iter()
            .max_by(|a, b| {
                a["gain_db"]
                    .as_f64()
                    .unwrap()
                    .total_cmp(&b["gain_db"].as_f64().unwrap())
            })
            .unwrap();
        let f = top["frequency_hz"].as_f64().unwrap();
        assert!((f - 166.9).abs() < 1.0, "{peaks:?}");
        for file in ["json", "csv", "svg"] {
            assert!(dir
                .path()
                .join(format!("raw/frequency_response_time.{file}"))
                .exists());
        }
        assert!(dir
            .path()
            .join("raw/frequency_response_time-coherence.svg")
            .exists());
        let coarse = rtid_json(
            &[
                "evaluate",
                "raw/frequency_response_time.json",
                "--json",
                "--segment-s",
                "0.5",
            ],
            dir.path(),
        );
        assert_eq!(coarse["resolution_hz"], 2.0);
        let text = rtid_ok(
            &["evaluate", "raw/frequency_response_time.json"],
            dir.path(),
        );
        assert!(
            text.contains("resonances") && text.contains("H1 with Welch averaging"),
            "{text}"
        );
        // Drop the 100th sample of the CSV (line 102: a comment line, the header).
        let csv = dir.path().join("raw/frequency_response_time.csv");
        let lines: Vec<String> = std::fs::read_to_string(&csv)
            .unwrap()
            .lines()
            .enumerate()
            .filter(|(i, _)| *i != 101)
            .map(|(_, l)| l.to_string())
            .collect();
        std::fs::write(&csv, lines.join("\n")).unwrap();
        let out = rtid(
            &["evaluate", "raw/frequency_response_time.json"],
            dir.path(),
        );
        assert_one_line_error(
            &out,
            &[
                "frequency_response_time.csv",
                "line 102",
                "time_s",
                "uniformly",
            ],
        );
    }
}

#[test]
fn a_reader_that_closes_the_pipe_early_is_not_an_error() {
    // `rtid modes … | head -0`: the reader is gone before the first line is written.
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args(["modes", "--preset", "worm-gear"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the rtid binary runs");
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = stderr(&out);
    assert!(
        out.status.success() && !err.contains("panicked"),
        "{}: {err}",
        out.status
    );
}

/// `rtid evaluate` writes plots only where `--plot` asks: the committed SVGs beside a
/// shipped record are never rewritten by evaluating it with other parameters.
#[test]
fn evaluate_writes_no_plot_unless_asked() {
    let dir = tempdir();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/real/emps");
    for f in ["emps_estimation.json", "emps_estimation.csv", "axis.json"] {
        std::fs::copy(root.join(f), dir.path().join(f)).unwrap();
    }
    std::fs::write(dir.path().join("emps_estimation.svg"), "committed").unwrap();
    let listing = || {
        let mut names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        names.sort();
        names
    };
    let before = listing();
    let args = ["evaluate", "emps_estimation.json", "--params", "axis.json"];
    let text = rtid_ok(&args, dir.path());
    assert!(text.contains("replayed on the model"), "{text}");
    assert_eq!(listing(), before);
    let svg = std::fs::read_to_string(dir.path().join("emps_estimation.svg")).unwrap();
    assert_eq!(svg, "committed");
    // Asked, the plots go where --plot says.
    rtid_ok(&[&args[..], &["--plot", "out.svg"]].concat(), dir.path());
    assert!(dir.path().join("out-effort.svg").exists());
}

/// The EMPS estimation record evaluated as a new user would: the friction law by
/// IDIM-LS, and the trace replayed on the published model (fixtures/real/emps) to the
/// published simulation error (2.10 µm RMS, 12.6 µm max, 2.41 N RMS; Janot et al.
/// 2019), with both plots written beside the output. A model of the wrong axis is one
/// clear error.
#[test]
fn evaluate_replays_the_emps_servo_trace_on_its_published_model() {
    let dir = tempdir();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/real/emps");
    let trace = root.join("emps_estimation.json");
    let (trace, axis) = (trace.to_str().unwrap(), root.join("axis.json"));
    let plot = dir.path().join("emps.svg");
    let v = rtid_json(
        &[
            "evaluate",
            trace,
            "--params",
            axis.to_str().unwrap(),
            "--json",
            "--plot",
            plot.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert_eq!(v["kind"], "servo_trace");
    assert_eq!(v["axis"], "linear");
    let e = &v["simulation_error"];
    let near = |x: &serde_json::Value, want: f64, tol: f64| {
        x.as_f64().is_some_and(|x| (x / want - 1.0).abs() < tol)
    };
    assert!(near(&e["position_rms"], 2.10e-6, 0.05), "{e}");
    assert!(near(&e["position_max"], 12.6e-6, 0.10), "{e}");
    assert!(near(&e["force_rms"], 2.41, 0.05), "{e}");
    let idim = &v["inverse_dynamics"];
    assert!(near(&idim["inertia"]["value"], 95.1089, 0.02), "{idim}");
    assert!(near(&idim["coulomb"]["value"], 20.3935, 0.02), "{idim}");
    assert!(plot.exists() && dir.path().join("emps-effort.svg").exists());
    let out = rtid(
        &[
            "evaluate",
            trace,
            "--preset",
            "worm-gear",
            "--plot",
            plot.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert_one_line_error(&out, &["emps_estimation.json", "linear axis", "rotary"]);
}

/// `rtid experiment servo-trace` writes a trace of the model that `evaluate` reads
/// (here the worm preset: its IDIM-LS Coulomb friction is the friction at the motor,
/// fm + fw·Rg + ft·Rg·Rw = 0.335 N·m); a malformed move is one clear error naming the
/// option.
#[test]
fn experiment_servo_trace_writes_a_trace_of_the_model() {
    let dir = tempdir();
    let v = rtid_json(
        &[
            "experiment",
            "servo-trace",
            "--preset",
            "worm-gear",
            "--out",
            "trace",
            "--json",
        ],
        dir.path(),
    );
    assert_eq!(v["kind"], "servo_trace");
    assert_eq!(v["axis"], "rotary");
    let fc = v["inverse_dynamics"]["coulomb"]["value"].as_f64().unwrap();
    assert!((fc / 0.335 - 1.0).abs() < 0.02, "{fc}");
    for f in ["servo_trace.json", "servo_trace.csv", "servo_trace.svg"] {
        assert!(dir.path().join("trace").join(f).is_file(), "{f}");
    }
    for (moves, named) in [("0.1@fast", "fast"), ("0.1@-2", "-2")] {
        let out = rtid(
            &[
                "experiment",
                "servo-trace",
                "--preset",
                "worm-gear",
                "--moves",
                moves,
                "--out",
                "bad",
            ],
            dir.path(),
        );
        assert_one_line_error(&out, &["--moves", named]);
    }
}

/// ISO 230-2 on a linear axis, natively: a laser run written in mm and µm is
/// evaluated in µm (targets in mm), in the table, the JSON and the plot.
#[test]
fn evaluate_reports_a_linear_positioning_run_in_micrometres() {
    let dir = tempdir();
    let mut csv = String::from("target_mm,direction,run,deviation_um\n");
    for target in [0, 100, 200] {
        for (run, up) in [(1, 1.0), (2, 1.2)] {
            csv += &format!("{target},up,{run},{up}\n{target},down,{run},{}\n", -up);
        }
    }
    std::fs::write(dir.path().join("laser.csv"), csv).unwrap();
    std::fs::write(
        dir.path().join("laser.json"),
        r#"{"kind": "positioning", "data": "laser.csv", "mechanism": "X axis"}"#,
    )
    .unwrap();
    let v = rtid_json(&["evaluate", "laser.json", "--json"], dir.path());
    assert_eq!(v["unit"], "um");
    let b = v["axis"]["B"].as_f64().unwrap();
    assert!((b - 2.2).abs() < 1e-9, "B = x̄↑ − x̄↓ = 2.2 µm: {b}");
    assert_eq!(v["targets"][2]["target_mm"], 200.0);
    let text = rtid_ok(
        &["evaluate", "laser.json", "--plot", "laser.svg"],
        dir.path(),
    );
    assert!(
        text.contains("ISO 230-2 evaluation, µm") && text.contains("target mm"),
        "{text}"
    );
    let svg = std::fs::read_to_string(dir.path().join("laser.svg")).unwrap();
    assert!(
        svg.contains("µm") && svg.contains("mm"),
        "plot axes in mm and µm"
    );
}

/// The virtual tests on a linear axis (the EMPS carriage), natively: the ISO 230-2 run
/// written in mm and µm and reported in µm, the force curve in N and m with the
/// carriage's Coulomb friction (ft = 20.39 N) read back; a rotary option on it is one
/// clear error naming the option.
#[test]
fn the_virtual_tests_run_on_a_linear_axis_in_its_units() {
    let dir = tempdir();
    let axis = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/real/emps/axis.json");
    let axis = axis.to_str().unwrap();
    let v = rtid_json(
        &[
            "experiment",
            "positioning",
            "--params",
            axis,
            "--travel-mm",
            "100",
            "--target-step-mm",
            "50",
            "--runs",
            "2",
            "--out",
            "iso",
            "--json",
        ],
        dir.path(),
    );
    assert_eq!(v["unit"], "um");
    let targets: Vec<f64> = v["targets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["target_mm"].as_f64().unwrap())
        .collect();
    assert_eq!(targets, [0.0, 50.0, 100.0]);
    let csv = std::fs::read_to_string(dir.path().join("iso/positioning.csv")).unwrap();
    assert!(
        csv.contains("target_mm") && csv.contains("deviation_um"),
        "{csv}"
    );
    let v = rtid_json(
        &[
            "experiment",
            "torque-curve",
            "--params",
            axis,
            "--amplitude-mm",
            "50",
            "--periods",
            "1",
            "--out",
            "force",
            "--json",
        ],
        dir.path(),
    );
    let fc = v["friction_n"].as_f64().unwrap();
    assert!((fc / 20.3935 - 1.0).abs() < 0.03, "Fc = {fc} N");
    let csv = std::fs::read_to_string(dir.path().join("force/torque_curve.csv")).unwrap();
    assert!(
        csv.lines().nth(1).unwrap().contains("force_n"),
        "{csv:.200}"
    );
    let out = rtid(
        &[
            "experiment",
            "positioning",
            "--params",
            axis,
            "--target-step-deg",
            "30",
            "--out",
            "bad",
        ],
        dir.path(),
    );
    assert_one_line_error(&out, &["--target-step-deg", "linear"]);
}

/// `identify --band`: a spurious maximum outside the band (here a 4 dB ripple written
/// into the worm fixture at 400 Hz) is a "resonance" the model cannot match without
/// it, and is not matched with it — the band gives the clean fixture's fit. (The
/// resonance fit, named: the fixture has phase, whose default is the whole curve.)
#[test]
fn identify_in_a_band_ignores_a_ripple_outside_it() {
    let dir = tempdir();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/worm-gear");
    let csv = std::fs::read_to_string(root.join("frequency_response.csv")).unwrap();
    let rippled: Vec<String> = csv
        .lines()
        .map(|line| match line.split_once(',') {
            Some(("400.0", rest)) => {
                let (gain, tail) = rest.split_once(',').unwrap();
                format!("400.0,{},{tail}", gain.parse::<f64>().unwrap() + 4.0)
            }
            _ => line.to_string(),
        })
        .collect();
    std::fs::write(dir.path().join("fr.csv"), rippled.join("\n") + "\n").unwrap();
    let manifest = std::fs::read_to_string(root.join("frequency_response.json")).unwrap();
    std::fs::write(
        dir.path().join("fr.json"),
        manifest.replace("frequency_response.csv", "fr.csv"),
    )
    .unwrap();
    let fit = |file: &str, band: Option<&str>| {
        let mut args = vec![
            "identify",
            file,
            "--preset",
            "worm-gear",
            "--model",
            "linear",
            "--objective",
            "resonance",
            "--json",
        ];
        if let Some(b) = band {
            args.extend(["--band", b]);
        }
        rtid_json(&args, dir.path())
    };
    let measured = |v: &serde_json::Value| {
        v["residuals"][0]["detail"]["measured_hz"]
            .as_array()
            .unwrap()
            .len()
    };
    let clean_path = root.join("frequency_response.json");
    let clean = fit(clean_path.to_str().unwrap(), None);
    let rippled = fit("fr.json", None);
    let banded = fit("fr.json", Some("100..300"));
    assert_eq!(
        (measured(&clean), measured(&rippled), measured(&banded)),
        (2, 3, 2)
    );
    for name in ["Kw", "Kg"] {
        let (a, b) = (
            clean["parameters"][name].as_f64().unwrap(),
            banded["parameters"][name].as_f64().unwrap(),
        );
        assert!(
            (b / a - 1.0).abs() < 1e-3,
            "{name}: {b} in the band, {a} on the clean curve"
        );
    }
    let out = rtid(
        &[
            "identify",
            "fr.json",
            "--preset",
            "worm-gear",
            "--band",
            "300..100",
        ],
        dir.path(),
    );
    assert_one_line_error(&out, &["--band", "300..100"]);
}

/// A UTF-8 byte-order mark at the start of a JSON manifest or parameter file (as some
/// Windows editors write) is accepted, as it is in CSV, not refused at "line 1,
/// column 1".
#[test]
fn json_files_with_a_byte_order_mark_are_read() {
    let dir = tempdir();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let with_bom = |from: &Path, to: &str| {
        let text = std::fs::read_to_string(from).unwrap();
        std::fs::write(dir.path().join(to), format!("\u{feff}{text}")).unwrap();
    };
    with_bom(
        &root.join("worm-gear/frequency_response.json"),
        "frequency_response.json",
    );
    std::fs::copy(
        root.join("worm-gear/frequency_response.csv"),
        dir.path().join("frequency_response.csv"),
    )
    .unwrap();
    with_bom(&root.join("presets/worm-gear.json"), "worm.json");
    let v = rtid_json(
        &["evaluate", "frequency_response.json", "--json"],
        dir.path(),
    );
    assert_eq!(v["kind"], "frequency_response");
    rtid_ok(&["modes", "--params", "worm.json"], dir.path());
}

/// Inputs are never outputs: `identify … --out` (or `--save-params`, `--checkpoint`)
/// and `evaluate --plot` naming a manifest, its CSV or the parameter file are one
/// clear error, and the input is left as it was.
#[test]
fn an_output_over_an_input_is_refused_and_the_input_kept() {
    let dir = tempdir();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/worm-gear");
    for f in ["frequency_response.json", "frequency_response.csv"] {
        std::fs::copy(root.join(f), dir.path().join(f)).unwrap();
    }
    let before = std::fs::read(dir.path().join("frequency_response.csv")).unwrap();
    for (option, target) in [
        ("--out", "frequency_response.json"),
        ("--out", "frequency_response.csv"),
        ("--checkpoint", "./frequency_response.json"),
    ] {
        let out = rtid(
            &[
                "identify",
                "frequency_response.json",
                "--preset",
                "worm-gear",
                option,
                target,
            ],
            dir.path(),
        );
        assert_one_line_error(&out, &[option, target, "input"]);
    }
    let out = rtid(
        &[
            "evaluate",
            "frequency_response.json",
            "--plot",
            "frequency_response.csv",
        ],
        dir.path(),
    );
    assert_one_line_error(&out, &["--plot", "frequency_response.csv", "input"]);
    assert_eq!(
        std::fs::read(dir.path().join("frequency_response.csv")).unwrap(),
        before
    );
}

/// `simulate --out` and `experiment … --out DIR` never write over the parameter file
/// they read (here named like the test's own manifest, in the output folder).
#[test]
fn simulate_and_experiments_keep_their_parameter_file() {
    let dir = tempdir();
    let preset = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/presets/worm-gear.json");
    std::fs::create_dir(dir.path().join("d")).unwrap();
    std::fs::copy(&preset, dir.path().join("d/torque_curve.json")).unwrap();
    let before = std::fs::read(dir.path().join("d/torque_curve.json")).unwrap();
    let out = rtid(
        &[
            "simulate",
            "--params",
            "d/torque_curve.json",
            "--input",
            "none",
            "--duration-s",
            "0.01",
            "--out",
            "d/torque_curve.json",
        ],
        dir.path(),
    );
    assert_one_line_error(&out, &["--out", "torque_curve.json", "input"]);
    let out = rtid(
        &[
            "experiment",
            "torque-curve",
            "--params",
            "d/torque_curve.json",
            "--periods",
            "1",
            "--out",
            "d",
        ],
        dir.path(),
    );
    assert_one_line_error(&out, &["--out", "torque_curve.json", "input"]);
    assert_eq!(
        std::fs::read(dir.path().join("d/torque_curve.json")).unwrap(),
        before
    );
}

/// The two-mass bench's multisine record (fixtures/real/two-mass, MIT) evaluated as a
/// drive engineer would: both channels, each one's resonances and antiresonances and
/// nothing else, the two-mass ratios, and the reference values of the record's README
/// (load/motor peak 53.5–53.9 Hz, motor/current resonance 76.2 ± 0.3 Hz and
/// antiresonance 53.9 ± 0.3 Hz, Jl/Jm within 3 % of 1.00, k/Jl within 2 % of 1.15e5).
#[test]
fn evaluate_gives_both_channels_of_the_two_mass_multisine_record() {
    let dir = tempdir();
    let record =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/real/two-mass/multisine_a.json");
    let record = record.to_str().unwrap();
    let plot = dir.path().join("bench.svg");
    let plot = plot.to_str().unwrap();
    let v = rtid_json(&["evaluate", record, "--json", "--plot", plot], dir.path());
    assert_eq!(v["estimator"], "periodic");
    let hz = |key: &str| -> Vec<f64> {
        v[key]
            .as_array()
            .unwrap_or_else(|| panic!("{key} in {v}"))
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let (table, motor) = (hz("table_resonances_hz"), hz("motor_resonances_hz"));
    let anti = hz("motor_antiresonances_hz");
    assert!(hz("table_antiresonances_hz").is_empty());
    assert!(
        table.len() == 1 && (53.5..=53.9).contains(&table[0]),
        "{table:?}"
    );
    assert!(
        motor.len() == 1 && (motor[0] - 76.2).abs() < 0.3,
        "{motor:?}"
    );
    assert!(anti.len() == 1 && (anti[0] - 53.9).abs() < 0.3, "{anti:?}");
    let r = &v["two_mass"];
    let ratio = r["inertia_ratio"].as_f64().unwrap();
    let k = r["k_over_jl"].as_f64().unwrap();
    assert!(
        (ratio - 1.0).abs() < 0.03 && (k / 1.15e5 - 1.0).abs() < 0.02,
        "{r}"
    );
    assert!(dir.path().join("bench.svg").exists());
    assert!(dir.path().join("bench-coherence.svg").exists());
    let text = rtid_ok(&["evaluate", record, "--plot", plot], dir.path());
    assert!(
        text.contains("without a torque constant") && text.contains("Jl/Jm = 1.00"),
        "{text}"
    );
}

/// A virtual multisine record of the two-mass preset gives back the model: the
/// motor-free mode √(Kw(1/Jm + 1/Jt)) = 76.3 Hz, the motor-held one √(Kw/Jt) = 54.0 Hz
/// on both channels, Jt/Jm = 1 and Kw/Jt = 1.15e5 rad²/s² (friction on: within 3 % and
/// 2 %). A random-odd multisine measures the friction's odd distortion at the lines it
/// leaves out.
#[test]
fn a_virtual_two_mass_multisine_gives_back_the_model() {
    let dir = tempdir();
    let run = |lines: &str, out: &str| {
        rtid_json(
            &[
                "experiment",
                "frequency-response-time",
                "--preset",
                "two-mass",
                "--excitation",
                "multisine",
                "--lines",
                lines,
                "--from-hz",
                "11",
                "--to-hz",
                "250",
                "--amplitude-nm",
                "0.2",
                "--sample-rate-hz",
                "2500",
                "--periods",
                "10",
                "--out",
                out,
                "--quiet",
                "--json",
            ],
            dir.path(),
        )
    };
    let v = run("full", "full");
    let first = |key: &str| v[key][0].as_f64().unwrap_or_else(|| panic!("{key}: {v}"));
    assert!((first("motor_resonances_hz") - 76.3).abs() < 0.5, "{v}");
    assert!((first("motor_antiresonances_hz") - 54.0).abs() < 0.5, "{v}");
    assert!((first("table_resonances_hz") - 54.0).abs() < 0.5, "{v}");
    let r = &v["two_mass"];
    assert!(
        (r["inertia_ratio"].as_f64().unwrap() - 1.0).abs() < 0.03,
        "{r}"
    );
    assert!(
        (r["k_over_jl"].as_f64().unwrap() / 1.15e5 - 1.0).abs() < 0.02,
        "{r}"
    );
    let manifest =
        std::fs::read_to_string(dir.path().join("full/frequency_response_time.json")).unwrap();
    assert!(
        manifest.contains("\"excitation\": \"multisine\""),
        "{manifest}"
    );
    let odd = run("random-odd", "odd");
    let bands = odd["motor"]["distortion"].as_array().unwrap();
    assert!(
        bands.iter().any(|b| b["odd"]["detected"] == true),
        "friction distorts at the odd lines left out: {bands:?}"
    );
}

/// A current-driven record must be a multisine; a period that is not a whole number
/// of samples is named.
#[test]
fn a_multisine_record_with_a_wrong_period_is_one_clear_error() {
    let dir = tempdir();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/real/two-mass");
    std::fs::copy(
        root.join("multisine_a.csv"),
        dir.path().join("multisine_a.csv"),
    )
    .unwrap();
    let manifest = std::fs::read_to_string(root.join("multisine_a.json")).unwrap();
    let odd = manifest.replace("\"period_s\": 1,", "\"period_s\": 1.00001,");
    assert_ne!(odd, manifest);
    std::fs::write(dir.path().join("odd.json"), odd).unwrap();
    let out = rtid(&["evaluate", "odd.json"], dir.path());
    assert_one_line_error(&out, &["odd.json", "period_s"]);
    let broadband = manifest.replace("\"excitation\": \"multisine\",", "");
    std::fs::write(dir.path().join("broadband.json"), broadband).unwrap();
    let out = rtid(&["evaluate", "broadband.json"], dir.path());
    assert_one_line_error(&out, &["broadband.json", "multisine"]);
}

/// Work is estimated before it starts: sizes that would allocate terabytes, run for
/// ever or stall the eigen-solver are refused at once, naming the options and the
/// limit (issue 13). Numbers in the messages stay short.
#[test]
fn absurd_sizes_and_values_are_refused_before_any_work() {
    let sine = "sine:freq_hz=100,amp_nm=5";
    refused_at_once(&[
        (
            &[
                "experiment",
                "frequency-response",
                "--preset",
                "worm-gear",
                "--to-hz",
                "1e12",
                "--out",
                "a",
            ],
            &["--to-hz", "frequencies", "RTID_ALLOW_LARGE"],
        ),
        (
            &[
                "experiment",
                "frequency-response",
                "--preset",
                "worm-gear",
                "--step-hz",
                "1e-300",
                "--out",
                "a",
            ],
            &["--step-hz", "limit"],
        ),
        (
            &[
                "experiment",
                "torque-curve",
                "--preset",
                "worm-gear",
                "--periods",
                "1e9",
                "--out",
                "a",
            ],
            &["--periods", "simulated seconds", "3600"],
        ),
        (
            &[
                "experiment",
                "torque-curve",
                "--preset",
                "worm-gear",
                "--period-s",
                "1e12",
                "--out",
                "a",
            ],
            &["--period-s", "simulated seconds"],
        ),
        (
            &[
                "experiment",
                "positioning",
                "--preset",
                "worm-gear",
                "--runs",
                "4000000000",
                "--out",
                "a",
            ],
            &["--runs", "readings"],
        ),
        (
            &[
                "experiment",
                "positioning",
                "--preset",
                "worm-gear",
                "--target-step-deg",
                "1e-300",
                "--out",
                "a",
            ],
            &["--target-step-deg 1e-300", "targets"],
        ),
        (
            &[
                "simulate",
                "--preset",
                "worm-gear",
                "--duration-s",
                "1e12",
                "--input",
                sine,
                "--out",
                "r.csv",
            ],
            &["--duration-s", "integration steps"],
        ),
        // Beyond ±1e15 a value is no drive test's, whatever work it would make: named
        // as the option, not as the file's cell or the arithmetic it would break.
        (
            &[
                "experiment",
                "positioning",
                "--preset",
                "worm-gear",
                "--noise-arcsec",
                "1e308",
                "--out",
                "a",
            ],
            &["--noise-arcsec 1e308", "beyond ±1e15"],
        ),
        (
            &[
                "experiment",
                "unbalance",
                "--preset",
                "worm-gear",
                "--mass-kg",
                "1e308",
                "--out",
                "a",
            ],
            &["--mass-kg 1e308", "beyond ±1e15"],
        ),
    ]);
}

/// More of the same: absurd sizes and values of a simulation.
#[test]
fn absurd_sizes_and_values_of_a_simulation_are_refused_before_any_work() {
    let sine = "sine:freq_hz=100,amp_nm=5";
    refused_at_once(&[
        (
            &[
                "simulate",
                "--preset",
                "worm-gear",
                "--dt-s",
                "5e-324",
                "--input",
                sine,
                "--duration-s",
                "0.1",
                "--out",
                "r.csv",
            ],
            &["--dt-s", "integration steps"],
        ),
        (
            &[
                "simulate",
                "--preset",
                "worm-gear",
                "--set",
                "Kw=1e308",
                "--input",
                sine,
                "--duration-s",
                "0.1",
                "--out",
                "r.csv",
            ],
            &["Kw = 1e308", "typo"],
        ),
        (
            &[
                "simulate",
                "--preset",
                "worm-gear",
                "--set",
                "r=1e-300",
                "--input",
                sine,
                "--duration-s",
                "0.1",
                "--out",
                "r.csv",
            ],
            &["r = 1e-300", "typo"],
        ),
    ]);
}

/// And of the experiments and modes.
#[test]
fn absurd_values_of_experiments_and_modes_are_refused_before_any_work() {
    refused_at_once(&[
        (
            &[
                "experiment",
                "frequency-response-time",
                "--preset",
                "worm-gear",
                "--excitation",
                "stepped-sine",
                "--step-hz",
                "1e-300",
                "--out",
                "a",
            ],
            &["--step-hz", "frequencies"],
        ),
        (
            &["modes", "--preset", "worm-gear", "--set", "Jm=1e-14"],
            &["theta_m", "rad/s", "typo"],
        ),
        (
            &["modes", "--preset", "worm-gear", "--set", "Kw=1e308"],
            &["Kw = 1e308"],
        ),
        (
            &[
                "experiment",
                "frequency-response",
                "--preset",
                "worm-gear",
                "--amplitude-nm",
                "-1",
                "--out",
                "a",
            ],
            &["--amplitude-nm -1", "positive"],
        ),
        (
            &[
                "experiment",
                "frequency-response-time",
                "--preset",
                "worm-gear",
                "--sample-rate-hz",
                "-5",
                "--out",
                "a",
            ],
            &["--sample-rate-hz -5", "positive"],
        ),
    ]);
}

/// Each of `cases` fails at once with one short line holding its needles, and
/// writes nothing.
fn refused_at_once(cases: &[(&[&str], &[&str])]) {
    let dir = tempdir();
    for (args, needles) in cases {
        let out = rtid(args, dir.path());
        let line = assert_one_line_error(&out, needles);
        assert!(line.len() < 400, "{args:?}: a short message: {line}");
        assert!(
            !line.contains("00000000"),
            "{args:?}: a readable number: {line}"
        );
    }
    assert!(!dir.path().join("a").exists() && !dir.path().join("r.csv").exists());
}

/// A negative value reaches the option's own check instead of clap's "unexpected
/// argument": the option is named either way.
#[test]
fn a_negative_value_names_its_option() {
    let dir = tempdir();
    let out = rtid(
        &[
            "identify",
            "x.json",
            "--preset",
            "worm-gear",
            "--starts",
            "-2",
        ],
        dir.path(),
    );
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.lines().next().unwrap_or("").contains("--starts"),
        "{err}"
    );
    // A negative preload means a brake the other way: accepted as a value.
    let out = rtid(
        &[
            "experiment",
            "frequency-response",
            "--preset",
            "worm-gear",
            "--preload-nm",
            "-3",
            "--from-hz",
            "100",
            "--to-hz",
            "110",
            "--out",
            "neg",
            "--quiet",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

/// Ctrl-C (a real SIGINT) at several moments of an identification, then `--resume`:
/// the same parameters as the run that was never interrupted, at every fidelity
/// (issue 13). A moment after the run has finished resumes a finished checkpoint.
#[test]
fn an_identification_stopped_by_sigint_resumes_to_the_uninterrupted_result() {
    let dir = tempdir();
    // The fixture without its phase: the resonance fit of Kw and Kg, which stops at
    // the same point from any path. Its complex fit (the default with phase: Kw, Kg,
    // Ciw, Cig; Ciw at its bound on this 10–600 Hz record) resumed to 2e-5 of Kg, not
    // 1e-9: its search stops on the cost's relative change along a flat direction.
    let source =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/worm-gear/frequency_response");
    let csv = std::fs::read_to_string(source.with_extension("csv")).unwrap();
    let gain_only: String = csv
        .lines()
        .map(|l| {
            if l.starts_with('#') {
                format!("{l}\n")
            } else {
                let c: Vec<&str> = l.split(',').collect();
                format!("{},{}\n", c[0], c[1])
            }
        })
        .collect();
    std::fs::write(dir.path().join("frequency_response.csv"), gain_only).unwrap();
    std::fs::copy(
        source.with_extension("json"),
        dir.path().join("frequency_response.json"),
    )
    .unwrap();
    let fr = dir.path().join("frequency_response.json");
    let fr = fr.to_str().unwrap();
    let args = |model: &'static str| -> Vec<String> {
        [
            "identify",
            fr,
            "--preset",
            "worm-gear",
            "--set",
            "Kw=4.34e5",
            "--set",
            "Kg=1190",
            "--model",
            model,
            "--quiet",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let parameters = |path: &Path| -> Vec<f64> {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        ["Kw", "Kg"]
            .iter()
            .map(|n| v["parameters"][n].as_f64().unwrap())
            .collect()
    };
    for model in ["linear", "nonlinear"] {
        let mut whole = args(model);
        whole.extend(["--out".into(), "whole.json".into()]);
        let whole: Vec<&str> = whole.iter().map(String::as_str).collect();
        rtid_ok(&whole, dir.path());
        let want = parameters(&dir.path().join("whole.json"));
        for delay_ms in [100, 400, 3000] {
            let ck = dir.path().join(format!("{model}-{delay_ms}.ck.json"));
            let _ = std::fs::remove_file(&ck);
            let mut first = args(model);
            first.extend([
                "--checkpoint".into(),
                ck.to_str().unwrap().into(),
                "--out".into(),
                "first.json".into(),
            ]);
            let out = interrupted(&first, dir.path(), delay_ms);
            assert!(
                out.status.success(),
                "{model} @ {delay_ms} ms: {}",
                stderr(&out)
            );
            let mut again = first.clone();
            again.push("--resume".into());
            let again: Vec<&str> = again.iter().map(String::as_str).collect();
            rtid_ok(&again, dir.path());
            let got = parameters(&dir.path().join("first.json"));
            for (g, w) in got.iter().zip(&want) {
                assert!(
                    ((g - w) / w).abs() < 1e-9,
                    "{model} @ {delay_ms} ms: {got:?} against {want:?}"
                );
            }
        }
    }
}

/// A long simulation stopped by SIGINT or SIGTERM exits with 130 and leaves no
/// half-written temporary file behind (issue 13).
#[test]
fn an_interrupted_simulation_leaves_no_temporary_file() {
    use std::process::{Command, Stdio};
    for signal in [libc::SIGINT, libc::SIGTERM] {
        let dir = tempdir();
        let child = Command::new(env!("CARGO_BIN_EXE_rtid"))
            .args([
                "simulate",
                "--preset",
                "worm-gear",
                "--input",
                "sine:freq_hz=100,amp_nm=5",
                "--duration-s",
                "100",
                "--sample-s",
                "1e-5",
                "--out",
                "run.csv",
            ])
            .current_dir(dir.path())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let started = std::time::Instant::now();
        while std::fs::read_dir(dir.path()).unwrap().count() == 0 {
            assert!(
                started.elapsed().as_secs() < 30,
                "no temporary file appeared"
            );
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        // SAFETY: a signal to the child this test started and still owns.
        unsafe {
            libc::kill(child.id() as i32, signal);
        }
        let out = child.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(130), "signal {signal}");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "signal {signal}: {left:?}");
    }
}

/// A manifest reads its data from its own folder only, and never a device.
#[test]
fn a_manifest_data_path_outside_its_folder_or_a_device_is_refused() {
    let dir = tempdir();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/worm-gear");
    let manifest = std::fs::read_to_string(root.join("torque_curve.json")).unwrap();
    for (name, data) in [("up.json", "../../etc/passwd"), ("abs.json", "/dev/zero")] {
        let text = manifest.replace("\"torque_curve.csv\"", &format!("\"{data}\""));
        assert_ne!(text, manifest);
        std::fs::write(dir.path().join(name), text).unwrap();
        let out = rtid(&["evaluate", name], dir.path());
        assert_one_line_error(&out, &[name, "data", "folder"]);
    }
    let out = rtid(
        &[
            "simulate",
            "--preset",
            "worm-gear",
            "--input",
            "file:/dev/zero",
            "--duration-s",
            "0.01",
            "--out",
            "r.csv",
        ],
        dir.path(),
    );
    let line = assert_one_line_error(&out, &["/dev/zero", "regular file"]);
    assert_eq!(line.matches("regular file").count(), 1, "said once: {line}");
}

/// A sweep stopped by a real SIGINT twice and resumed each time gives the bytes of
/// a sweep run straight through (issue 13): the rows finished before each stop are
/// kept, a row cut off mid-write is dropped and computed again.
#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier: three sweeps of ~6 s"
)]
fn a_sweep_stopped_by_sigint_resumes_to_the_bytes_of_a_straight_run() {
    // 400 points of the torque test: about 6 s on two cores with the points in
    // lanes, so that both stops (at 0.7 s and 1.5 s) fall mid-sweep (80 points, the
    // earlier size, finished within 1.5 s once the tests ran in lanes).
    let dir = tempdir();
    let args = |out: &str| -> Vec<String> {
        [
            "sweep",
            "--preset",
            "worm-gear",
            "--vary",
            "Jt=0.08..0.14:10",
            "--vary",
            "Kw=1e5..1e6:log:40",
            "--outputs",
            "torque_rms",
            "--quiet",
            "--out",
            out,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let straight: Vec<String> = args("straight.csv");
    rtid_ok(
        &straight.iter().map(String::as_str).collect::<Vec<_>>(),
        dir.path(),
    );
    let mut rows_seen = Vec::new();
    for (k, delay_ms) in [700, 1500].into_iter().enumerate() {
        let mut a = args("stopped.csv");
        if k > 0 {
            a.push("--resume".into());
        }
        let out = interrupted(&a, dir.path(), delay_ms);
        assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
        let text = std::fs::read_to_string(dir.path().join("stopped.csv")).unwrap();
        rows_seen.push(text.lines().filter(|l| !l.starts_with('#')).count() - 1);
    }
    assert!(
        rows_seen[0] > 0 && rows_seen[1] > rows_seen[0] && rows_seen[1] < 400,
        "rows after each stop: {rows_seen:?}"
    );
    let mut resume = args("stopped.csv");
    resume.push("--resume".into());
    rtid_ok(
        &resume.iter().map(String::as_str).collect::<Vec<_>>(),
        dir.path(),
    );
    assert_eq!(
        std::fs::read(dir.path().join("stopped.csv")).unwrap(),
        std::fs::read(dir.path().join("straight.csv")).unwrap(),
        "the resumed sweep differs from the straight one"
    );
}

/// `--profile` puts each fitted parameter's interval and points in the result, with a
/// plot each; a name that is not fitted is refused naming it (issue 14).
#[test]
fn identify_profile_writes_intervals_points_and_plots() {
    let dir = tempdir();
    let fr = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/worm-gear-noisy/frequency_response.json");
    let fr = fr.to_str().unwrap();
    let base = [
        "identify",
        fr,
        "--preset",
        "worm-gear",
        "--model",
        "linear",
        "--quiet",
    ];
    let out = rtid_ok(
        &[&base[..], &["--profile", "--out", "fit.json"]].concat(),
        dir.path(),
    );
    assert!(out.contains("95 % profile interval"), "{out}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("fit.json")).unwrap())
            .unwrap();
    for name in ["Kw", "Kg"] {
        let p = &v["profiles"][name];
        let (lo, hi) = (p["lower"].as_f64().unwrap(), p["upper"].as_f64().unwrap());
        let fitted = v["parameters"][name].as_f64().unwrap();
        assert!(lo < fitted && fitted < hi, "{name}: {p}");
        assert_eq!(p["level"].as_f64(), Some(0.95));
        let points = p["points"].as_array().unwrap();
        assert!(points.len() >= 5 && points.iter().all(|q| q.as_array().unwrap().len() == 2));
        let svg =
            std::fs::read_to_string(dir.path().join(format!("fit-profile-{name}.svg"))).unwrap();
        assert!(svg.starts_with("<svg"));
    }
    let out = rtid(&[&base[..], &["--profile", "Kw,Kx"]].concat(), dir.path());
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--profile Kx: not a fitted parameter (fitted: Cig, Ciw, Kg, Kw)"),
        "{err}"
    );
}

/// `rtid select` ranks fits of the same data and tests nested ones; fits of other
/// data and files that are not results are refused naming the file (issue 14).
#[test]
fn select_prefers_the_fit_the_data_ask_for_and_refuses_other_data() {
    let dir = tempdir();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let noisy = root.join("worm-gear-noisy/frequency_response.json");
    let clean = root.join("worm-gear/frequency_response.json");
    let fit = |data: &Path, extra: &[&str], out: &str| {
        let base = [
            "identify",
            data.to_str().unwrap(),
            "--preset",
            "worm-gear",
            "--model",
            "linear",
            "--objective",
            "gain-curve",
            "--quiet",
            "--out",
            out,
        ];
        rtid_ok(&[&base[..], extra].concat(), dir.path());
    };
    // Kg held 6 % off against Kg fitted.
    fit(&noisy, &["--fit", "Kw", "--set", "Kg=900"], "kw.json");
    fit(&noisy, &["--fit", "Kw,Kg"], "kw-kg.json");
    fit(&clean, &["--fit", "Kw,Kg"], "clean.json");
    let out = rtid_ok(&["select", "kw.json", "kw-kg.json", "--json"], dir.path());
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["criterion"], "aicc");
    assert_eq!(v["candidates"][0]["label"], "kw-kg.json", "{v}");
    assert!(v["candidates"][1]["delta"].as_f64().unwrap() > 10.0, "{v}");
    let t = &v["nested"][0];
    assert_eq!(
        (t["restricted"].as_str(), t["full"].as_str()),
        (Some("kw.json"), Some("kw-kg.json"))
    );
    assert!(t["p_value"].as_f64().unwrap() < 1e-6, "{t}");
    let text = rtid_ok(&["select", "kw.json", "kw-kg.json"], dir.path());
    assert!(
        text.contains("best by AICc: kw-kg.json (Kg, Kw) — decisively preferred"),
        "{text}"
    );
    for (args, culprit) in [
        (
            ["select", "kw.json", "clean.json"],
            "clean.json fits other residuals than kw.json",
        ),
        (
            ["select", "kw.json", noisy.to_str().unwrap()],
            "not a result file",
        ),
    ] {
        let out = rtid(&args, dir.path());
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.lines().count() == 1 && err.contains(culprit), "{err}");
    }
}

/// `rtid design` ranks candidate tests by the standard errors they would give: for
/// ft the unbalance test above the torque curve; bad candidates name themselves
/// (issue 14).
#[test]
fn design_ranks_the_unbalance_test_first_for_table_friction() {
    let dir = tempdir();
    let design = |candidates: &[&str], json: bool| -> Vec<String> {
        let mut args: Vec<String> = ["design", "--preset", "worm-gear", "--fit", "ft", "--quiet"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        for c in candidates {
            args.extend(["--candidate".to_string(), c.to_string()]);
        }
        if json {
            args.push("--json".into());
        }
        args
    };
    let args = design(&["torque-curve", "unbalance:mass_kg=10,radius_m=0.1"], true);
    let out = rtid_ok(
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        dir.path(),
    );
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let c = v["candidates"].as_array().unwrap();
    assert_eq!(c[0]["label"], "unbalance:mass_kg=10,radius_m=0.1", "{v}");
    let (first, second) = (
        c[0]["score"].as_f64().unwrap(),
        c[1]["score"].as_f64().unwrap(),
    );
    assert!(first < second, "{v}");
    assert!(c[0]["predicted_se"]["ft"].as_f64().unwrap() > 0.0);
    assert_eq!(c[0]["settings"]["speed_deg_per_min"].as_f64(), Some(360.0));
    for (candidate, culprit) in [
        ("torquecurve", "unknown test `torquecurve`"),
        ("unbalance:mass=3", "unknown setting `mass`"),
        ("unbalance:mass_kg=-3", "mass_kg"),
        (
            "frequency-response:step_hz=nan",
            "step_hz=`nan` is not a finite number",
        ),
    ] {
        let args = design(&[candidate, "torque-curve"], false);
        let out = rtid(
            &args.iter().map(String::as_str).collect::<Vec<_>>(),
            dir.path(),
        );
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.lines().count() == 1 && err.contains(culprit) && err.contains("--candidate"),
            "{err}"
        );
    }
}
