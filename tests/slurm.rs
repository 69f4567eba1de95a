//! The Slurm script of docs/sweeps.md ("Beyond one machine") run by a real Slurm: the
//! test starts a one-node cluster of its own (munged, slurmctld, slurmd, everything
//! in a temporary folder), submits the docs' script unchanged with a small sweep,
//! merges the shards with the docs' command and compares the result with the
//! unsharded sweep byte for byte; then it cancels a task mid-run and re-submits it
//! alone, which resumes its file. Needs root and Debian's `slurm-wlm` and `munge`
//! (.ci/run installs them).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The test's array: three shards of a Sobol sweep of 4·(5+2) = 28 points. Each
/// point costs about half a second of CPU, so a shard of 9 takes seconds: long
/// enough to cancel one mid-run.
const SHARDS: usize = 3;
const SAMPLES: &str = "4";
/// sbatch options overriding the script's `#SBATCH` lines for the small run (an
/// array of SHARDS tasks).
const SMALL: [&str; 2] = ["--array=1-3", "--cpus-per-task=1"];
/// Longest wait for an array to finish (the whole test takes about 40 s on two
/// cores shared with a build).
const PATIENCE: Duration = Duration::from_secs(180);

/// The commands the test runs, found on PATH or in /usr/sbin (not on a user's PATH
/// on Debian).
const TOOLS: [&str; 8] = [
    "munged",
    "mungekey",
    "slurmctld",
    "slurmd",
    "sbatch",
    "squeue",
    "scancel",
    "sinfo",
];

/// The search path of every command the test starts: the rtid under test first, so
/// that the jobs (sbatch passes its environment on) and the docs' merge line run it.
fn search_path() -> std::ffi::OsString {
    let rtid = Path::new(env!("CARGO_BIN_EXE_rtid")).parent().unwrap();
    let inherited = std::env::var_os("PATH").unwrap_or_default();
    let mut dirs = vec![rtid.to_path_buf()];
    dirs.extend(std::env::split_paths(&inherited));
    dirs.extend(["/usr/sbin".into(), "/sbin".into()]);
    std::env::join_paths(dirs).unwrap()
}

/// Fails once, naming everything missing, when Slurm or munge is not installed.
fn require_tools() {
    let path = search_path();
    let missing: Vec<&str> = TOOLS
        .into_iter()
        .filter(|t| !std::env::split_paths(&path).any(|d| d.join(t).is_file()))
        .collect();
    assert!(
        missing.is_empty(),
        "the Slurm test needs {missing:?} (.ci/run installs them: apt-get install slurm-wlm munge)"
    );
    // SAFETY: geteuid has no preconditions.
    let root = unsafe { libc::geteuid() } == 0;
    assert!(root, "the Slurm test starts slurmd, which must run as root");
}

/// The docs' script and the shell lines around its `sbatch`.
struct Docs {
    /// The fenced block naming `sweep.slurm`, as printed.
    script: String,
    /// The lines before `sbatch sweep.slurm` (making `logs/`).
    setup: Vec<String>,
    /// `rtid sweep merge …`.
    merge: String,
}

fn docs() -> Docs {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/sweeps.md");
    let text = std::fs::read_to_string(path).unwrap();
    let start = text
        .find("```bash\n#!/bin/bash\n# sweep.slurm")
        .expect("docs/sweeps.md has a ```bash block starting with `# sweep.slurm`")
        + "```bash\n".len();
    let len = text[start..].find("```").unwrap();
    let script = text[start..start + len].to_string();
    // The indented block after the script: its commands, without comments.
    let commands: Vec<String> = text[start + len + 3..]
        .lines()
        .skip_while(|l| l.trim().is_empty())
        .take_while(|l| l.starts_with("    "))
        .map(str::trim)
        .filter(|l| !l.starts_with('#'))
        .map(String::from)
        .collect();
    let sbatch = commands
        .iter()
        .position(|l| l.starts_with("sbatch sweep.slurm"))
        .expect("the docs submit with `sbatch sweep.slurm`");
    let merge = commands
        .iter()
        .find(|l| l.starts_with("rtid sweep merge"))
        .expect("the docs merge with `rtid sweep merge`")
        .clone();
    Docs {
        script,
        setup: commands[..sbatch].to_vec(),
        merge,
    }
}

/// `bash -c LINE` in `dir`, with the test's PATH.
fn shell(line: &str, dir: &Path) -> Output {
    Command::new("bash")
        .args(["-c", line])
        .current_dir(dir)
        .env("PATH", search_path())
        .output()
        .unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A one-node Slurm cluster of the test's own processes, stopped when dropped.
struct Cluster {
    daemons: Vec<Child>,
    conf: PathBuf,
    /// Kept (and named) when the test fails, for the daemons' logs.
    dir: Option<tempfile::TempDir>,
}

impl Cluster {
    fn start() -> Cluster {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().to_path_buf();
        let mut cluster = Cluster {
            daemons: Vec::new(),
            conf: root.join("slurm.conf"),
            dir: Some(dir),
        };
        cluster.start_munged();
        std::fs::write(&cluster.conf, slurm_conf(&root)).unwrap();
        for dir in ["state", "spool"] {
            std::fs::create_dir(root.join(dir)).unwrap();
        }
        // -D: in the foreground, so that the guard owns them.
        for daemon in ["slurmctld", "slurmd"] {
            let mut cmd = cluster.command(daemon);
            cmd.args(["-D", "-f"]).arg(&cluster.conf);
            cluster.daemons.push(spawn(cmd));
        }
        cluster.wait_until_idle();
        cluster
    }

    fn root(&self) -> &Path {
        self.dir.as_ref().unwrap().path()
    }

    /// munged with its key, socket, pid, seed and log in `munge/`: munged refuses a
    /// socket whose folders are not searchable by all.
    fn start_munged(&mut self) {
        let munge = self.root().join("munge");
        std::fs::create_dir(&munge).unwrap();
        use std::os::unix::fs::PermissionsExt;
        for dir in [self.root(), munge.as_path()] {
            std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o755)).unwrap();
        }
        let key = munge.join("munge.key");
        let out = self
            .command("mungekey")
            .arg("-c")
            .arg("-k")
            .arg(&key)
            .output()
            .unwrap();
        assert!(out.status.success(), "mungekey: {}", text(&out.stderr));
        let mut cmd = self.command("munged");
        cmd.arg("--foreground");
        for (option, file) in [
            ("--key-file", "munge.key"),
            ("--socket", "munge.socket"),
            ("--pid-file", "munged.pid"),
            ("--seed-file", "munged.seed"),
            ("--log-file", "munged.log"),
        ] {
            cmd.arg(format!("{option}={}", munge.join(file).display()));
        }
        self.daemons.push(spawn(cmd));
        let socket = munge.join("munge.socket");
        let t0 = Instant::now();
        while !socket.exists() {
            assert!(
                t0.elapsed() < Duration::from_secs(10),
                "munged: {}",
                self.logs()
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// A Slurm or munge command talking to this cluster.
    fn command(&self, program: &str) -> Command {
        let mut cmd = Command::new(program);
        cmd.env("PATH", search_path()).env("SLURM_CONF", &self.conf);
        cmd
    }

    /// Runs a client command and returns its stdout; fails with the logs otherwise.
    fn client(&self, program: &str, args: &[&str]) -> String {
        let out = self.command(program).args(args).output().unwrap();
        assert!(
            out.status.success(),
            "{program} {args:?}: {}\n{}",
            text(&out.stderr),
            self.logs()
        );
        text(&out.stdout)
    }

    fn wait_until_idle(&self) {
        let t0 = Instant::now();
        loop {
            let out = self
                .command("sinfo")
                .args(["-h", "-o", "%t"])
                .output()
                .unwrap();
            if text(&out.stdout).trim() == "idle" {
                return;
            }
            assert!(
                t0.elapsed() < Duration::from_secs(30),
                "the node did not come up: {}{}",
                text(&out.stderr),
                self.logs()
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// `sbatch --parsable ARGS… sweep.slurm` in `dir` with the small sweep's
    /// sizes in the environment; returns the job id.
    fn submit(&self, dir: &Path, args: &[&str]) -> String {
        let out = self
            .command("sbatch")
            .arg("--parsable")
            .args(args)
            .arg("sweep.slurm")
            .current_dir(dir)
            .env("SHARDS", SHARDS.to_string())
            .env("SAMPLES", SAMPLES)
            .output()
            .unwrap();
        assert!(out.status.success(), "sbatch: {}", text(&out.stderr));
        text(&out.stdout).trim().to_string()
    }

    /// Waits until no task of `job` is pending, running or completing.
    fn wait(&self, job: &str, dir: &Path) {
        let t0 = Instant::now();
        while !self.client("squeue", &["-h", "-j", job]).trim().is_empty() {
            assert!(
                t0.elapsed() < PATIENCE,
                "job {job} still running after {PATIENCE:?}: {}{}",
                job_logs(dir),
                self.logs()
            );
            std::thread::sleep(Duration::from_millis(200));
        }
    }

    /// The daemons' logs, for a failure's message.
    fn logs(&self) -> String {
        let mut all = String::new();
        for name in ["munge/munged.log", "slurmctld.log", "slurmd.log"] {
            let log = std::fs::read_to_string(self.root().join(name)).unwrap_or_default();
            all += &format!("\n--- {name} ---\n{log}");
        }
        all
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        // Jobs left by a failure first: slurmstepd outlives slurmd.
        let _ = self.command("scancel").args(["--user", "root"]).output();
        let t0 = Instant::now();
        while t0.elapsed() < Duration::from_secs(10) {
            let out = self.command("squeue").arg("-h").output();
            if out.map_or(true, |o| o.stdout.is_empty()) {
                break;
            }
            std::thread::sleep(Duration::from_millis(200));
        }
        for daemon in self.daemons.iter_mut().rev() {
            stop(daemon);
        }
        if std::thread::panicking() {
            let dir = self.dir.take().unwrap().keep();
            eprintln!("the cluster's files are kept in {}", dir.display());
        }
    }
}

fn spawn(mut cmd: Command) -> Child {
    cmd.stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

/// SIGTERM, then SIGKILL if the daemon has not ended within 10 s.
fn stop(child: &mut Child) {
    // SAFETY: a signal to a child this test started and has not reaped.
    unsafe {
        libc::kill(child.id() as i32, libc::SIGTERM);
    }
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(10) {
        if let Ok(Some(_)) = child.try_wait() {
            return;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let _ = child.kill();
    let _ = child.wait();
}

/// slurm.conf for one node on 127.0.0.1, every file in `root`, free ports, no
/// accounting and no cgroups (linuxproc tracks a job's processes by parentage): what
/// runs in a container without systemd.
fn slurm_conf(root: &Path) -> String {
    let (node, cpus) = this_node();
    let [ctld_port, slurmd_port] = free_ports();
    let r = root.display();
    format!(
        "ClusterName=rtid-test
SlurmctldHost={node}(127.0.0.1)
SlurmctldPort={ctld_port}
SlurmdPort={slurmd_port}
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket={r}/munge/munge.socket
CredType=cred/munge
StateSaveLocation={r}/state
SlurmdSpoolDir={r}/spool
SlurmctldPidFile={r}/slurmctld.pid
SlurmdPidFile={r}/slurmd.pid
SlurmctldLogFile={r}/slurmctld.log
SlurmdLogFile={r}/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
MailProg=/bin/true
KillWait=2
NodeName={node} NodeAddr=127.0.0.1 CPUs={cpus}
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
"
    )
}

/// This machine's node name and CPU count, as `slurmd -C` reports them.
fn this_node() -> (String, usize) {
    let out = Command::new("slurmd")
        .arg("-C")
        .env("PATH", search_path())
        .output()
        .unwrap();
    let report = text(&out.stdout);
    let field = |name: &str| -> String {
        report
            .split_whitespace()
            .find_map(|w| w.strip_prefix(name))
            .unwrap_or_else(|| panic!("no {name} in `slurmd -C`: {report}"))
            .to_string()
    };
    (field("NodeName="), field("CPUs=").parse().unwrap())
}

/// Two ports nobody listens on (both held while choosing, so they differ).
fn free_ports() -> [u16; 2] {
    let a = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let b = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    [a, b].map(|l| l.local_addr().unwrap().port())
}

/// A folder for one submission: the docs' script, unchanged, and its setup lines run.
fn job_dir(cluster: &Cluster, docs: &Docs, name: &str) -> PathBuf {
    let dir = cluster.root().join(name);
    std::fs::create_dir(&dir).unwrap();
    std::fs::write(dir.join("sweep.slurm"), &docs.script).unwrap();
    for line in &docs.setup {
        let out = shell(line, &dir);
        assert!(out.status.success(), "{line}: {}", text(&out.stderr));
    }
    dir
}

/// Every task's log, for a failure's message.
fn job_logs(dir: &Path) -> String {
    let mut all = String::new();
    for entry in std::fs::read_dir(dir.join("logs")).into_iter().flatten() {
        let path = entry.unwrap().path();
        let log = std::fs::read_to_string(&path).unwrap_or_default();
        all += &format!("\n--- {} ---\n{log}", path.display());
    }
    all
}

/// The docs' merge line in `dir`; returns `sweep.csv`'s bytes.
fn merge(cluster: &Cluster, docs: &Docs, dir: &Path) -> Vec<u8> {
    let out = shell(&docs.merge, dir);
    assert!(
        out.status.success(),
        "{}: {}{}{}",
        docs.merge,
        text(&out.stderr),
        job_logs(dir),
        cluster.logs()
    );
    std::fs::read(dir.join("sweep.csv")).unwrap()
}

/// The script's own `rtid sweep` arguments, taken by running it with `rtid` a
/// shell function that prints them, for task 1 of the small array.
fn script_arguments(cluster: &Cluster, docs: &Docs) -> Vec<String> {
    let dir = job_dir(cluster, docs, "arguments");
    let out = Command::new("bash")
        .args(["-c", "rtid() { printf '%s\\0' \"$@\"; }; . ./sweep.slurm"])
        .current_dir(&dir)
        .env("SLURM_ARRAY_TASK_ID", "1")
        .env("SLURM_CPUS_PER_TASK", "1")
        .env("SHARDS", SHARDS.to_string())
        .env("SAMPLES", SAMPLES)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    text(&out.stdout)
        .split_terminator('\0')
        .map(String::from)
        .collect()
}

/// The same sweep unsharded: the script's arguments without `--shard`, `--threads`
/// and `--out`. Returns the file's bytes.
fn unsharded(cluster: &Cluster, docs: &Docs) -> Vec<u8> {
    let mut args = Vec::new();
    let mut words = script_arguments(cluster, docs).into_iter();
    while let Some(w) = words.next() {
        match w.as_str() {
            "--shard" | "--threads" | "--out" => {
                words.next();
            }
            _ => args.push(w),
        }
    }
    let out_file = cluster.root().join("unsharded.csv");
    let out = Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args(&args)
        .current_dir(cluster.root())
        .arg("--out")
        .arg(&out_file)
        .output()
        .unwrap();
    assert!(out.status.success(), "rtid {args:?}: {}", text(&out.stderr));
    std::fs::read(out_file).unwrap()
}

/// The complete rows of a sweep file (a cut-off last line is not one).
fn complete_rows(path: &Path) -> usize {
    let bytes = std::fs::read(path).unwrap_or_default();
    let end = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let lines = text(&bytes[..end]);
    // Less the column names' line.
    lines
        .lines()
        .filter(|l| !l.starts_with('#'))
        .count()
        .saturating_sub(1)
}

/// Waits until task 2's file has rows, then cancels the task; returns the rows it
/// kept. Fails if the task finished first.
fn cancel_mid_run(cluster: &Cluster, job: &str, dir: &Path, rows: usize) -> usize {
    let file = dir.join("shards/part-2.csv");
    let t0 = Instant::now();
    while complete_rows(&file) == 0 {
        assert!(
            t0.elapsed() < PATIENCE,
            "task 2 wrote no row: {}",
            job_logs(dir)
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    cluster.client("scancel", &[&format!("{job}_2")]);
    cluster.wait(job, dir);
    let kept = complete_rows(&file);
    assert!(
        (1..rows).contains(&kept),
        "task 2 kept {kept} of its {rows} rows: cancelled too late"
    );
    kept
}

#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier: starts a Slurm cluster (needs slurm-wlm, munge and root)"
)]
fn the_docs_slurm_array_merges_to_the_unsharded_sweep_and_a_cancelled_task_resumes() {
    require_tools();
    let docs = docs();
    let cluster = Cluster::start();
    let want = unsharded(&cluster, &docs);
    let dir = job_dir(&cluster, &docs, "straight");
    let job = cluster.submit(&dir, &SMALL);
    cluster.wait(&job, &dir);
    assert!(
        merge(&cluster, &docs, &dir) == want,
        "the merged shards differ from the unsharded sweep"
    );
    a_cancelled_task_resubmitted_resumes(&cluster, &docs, &want);
}

/// Task 2 cancelled mid-run (Slurm's SIGTERM, SIGKILL after KillWait), then
/// re-submitted alone as the docs say: it keeps its rows and computes the rest, and
/// the merge is again the unsharded sweep.
fn a_cancelled_task_resubmitted_resumes(cluster: &Cluster, docs: &Docs, want: &[u8]) {
    let points = want
        .split(|&b| b == b'\n')
        .filter(|l| l.first().is_some_and(u8::is_ascii_digit))
        .count();
    // Shard 2 holds points 1, 1 + N, 1 + 2N, …
    let rows = (points + SHARDS - 2) / SHARDS;
    let dir = job_dir(cluster, docs, "cancelled");
    let job = cluster.submit(&dir, &SMALL);
    let kept = cancel_mid_run(cluster, &job, &dir, rows);
    // rtid ends between rows on SIGTERM, so the shard has no cut-off line: merge
    // counts its points without a row, names the shard's file and says to resume.
    let out = shell(&docs.merge, &dir);
    let unfinished = format!("shards/part-2.csv ({} of {rows} rows missing)", rows - kept);
    assert!(
        !out.status.success()
            && text(&out.stderr).contains(&unfinished)
            && text(&out.stderr).contains("--resume"),
        "merge with a cancelled shard: {}",
        text(&out.stderr)
    );
    let again = cluster.submit(&dir, &["--array=2", "--cpus-per-task=1"]);
    cluster.wait(&again, &dir);
    let log = std::fs::read_to_string(dir.join("logs/shard-2.log")).unwrap();
    let summary = format!(
        "shard 2/{SHARDS}, {rows} rows ({} computed now, 0 failed)",
        rows - kept
    );
    assert!(
        log.contains(&summary),
        "the resumed task's log lacks `{summary}`: {log}"
    );
    // The script appends: the cancelled run's end is still in the log.
    assert!(
        log.contains("CANCELLED"),
        "the cancelled run's log is gone: {log}"
    );
    assert!(
        merge(cluster, docs, &dir) == want,
        "the merged shards after the resumed task differ from the unsharded sweep"
    );
}
