//! The deployment scripts of `deploy/` (docs/distributed.md): the task script
//! both cluster engines run, the merge script, and a whole render split
//! across a real one-node Slurm cluster started by the test — a job array
//! submitted by `deploy/slurm/submit.sh` rendering with the real `lumen`, one
//! task requeued while it runs and resuming from its part file, one killed
//! half-way, the merge job running once every task has ended and refusing the
//! unfinished part, the killed index rerun as docs/distributed.md says, and
//! the merged image compared, byte for byte, with a one-machine render.
//!
//! The Slurm test needs Slurm and munge (Debian: `slurm-wlm munge`) and root,
//! which slurmd needs to start jobs. Without them it says it is skipped and
//! passes, unless `LUMEN_REQUIRE_SLURM=1` (set by `.ci/run`), when it fails.

mod lumen_process;

use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::fs;
use std::io::Write;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::thread::sleep;
use std::time::{Duration, Instant};

/// The `lumen` the cluster runs.
const LUMEN: &str = env!("CARGO_BIN_EXE_lumen");

/// The repository's `deploy/` directory.
fn deploy_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("deploy")
}

/// A fresh, empty directory under the system's temporary directory. Short
/// paths matter: munge and slurmd put Unix sockets in it, whose paths are
/// limited to about 100 bytes.
fn fresh_dir(name: &str) -> PathBuf {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("lumen-{name}-{}-{n}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// A fresh directory (see [`fresh_dir`]) and its empty `parts` directory.
fn with_parts(name: &str) -> (PathBuf, PathBuf) {
    let dir = fresh_dir(name);
    let parts = dir.join("parts");
    fs::create_dir(&parts).unwrap();
    (dir, parts)
}

/// The file of part `index` of `count` in `parts`.
fn part_file(parts: &Path, index: u32, count: u32) -> PathBuf {
    lumen::part::file_name(parts, lumen::part::Part { index, count })
}

/// Writes an executable script. A child process writes it, so that this
/// process never holds the file open: a test thread that spawned a command
/// meanwhile would inherit the open file until its exec, and running the
/// script then fails with "Text file busy" (ETXTBSY).
fn write_executable(path: &Path, text: &str) {
    let mut child = Command::new("sh")
        .args(["-c", "cat > \"$1\" && chmod 755 \"$1\"", "sh"])
        .arg(path)
        .stdin(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(text.as_bytes())
        .unwrap();
    assert!(
        child.wait().unwrap().success(),
        "writing {}",
        path.display()
    );
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A command with none of the task variables of the environment the tests run
/// in (they may themselves run in a Slurm job or a Kubernetes pod), so that
/// only what a test sets reaches the scripts.
fn clean_command(program: impl AsRef<OsStr>) -> Command {
    let mut cmd = Command::new(program);
    for (key, _) in std::env::vars_os() {
        let key = key.to_string_lossy();
        if key.starts_with("SLURM_")
            || key.starts_with("SBATCH_")
            || key.starts_with("SQUEUE_")
            || key.starts_with("LUMEN_")
            || key == "JOB_COMPLETION_INDEX"
        {
            cmd.env_remove(&*key);
        }
    }
    cmd
}

// ---------------------------------------------------------------------------
// deploy/task.sh and deploy/merge.sh by hand: no cluster needed.

/// A stand-in for lumen that prints each argument on a line of stdout, leaves
/// a mark that it ran, and exits with `$STUB_STATUS` (default 0).
fn echo_stub(dir: &Path) -> PathBuf {
    let stub = dir.join("echo-lumen");
    write_executable(
        &stub,
        &format!(
            "#!/bin/sh\ntouch '{}'\nprintf '%s\\n' \"$@\"\nexit \"${{STUB_STATUS:-0}}\"\n",
            dir.join("ran").display()
        ),
    );
    stub
}

/// Runs `deploy/NAME` with `sh` and the given variables, in a clean
/// environment pointing `LUMEN_BIN` at the echo stub.
fn run_script(name: &str, dir: &Path, vars: &[(&str, &str)]) -> Output {
    let _ = fs::remove_file(dir.join("ran"));
    let mut cmd = clean_command("sh");
    cmd.arg(deploy_dir().join(name))
        .env("LUMEN_BIN", echo_stub(dir))
        .current_dir(dir);
    for (k, v) in vars {
        cmd.env(k, v);
    }
    cmd.output().unwrap()
}

fn lines(out: &Output) -> Vec<String> {
    text(&out.stdout).lines().map(str::to_owned).collect()
}

/// The arguments task.sh gives lumen for part `k` of `n`, before LUMEN_ARGS.
fn task_args(parts: &Path, k: u32, n: u32, resume: bool) -> Vec<String> {
    let mut args = vec![
        "render".to_owned(),
        "cover".to_owned(),
        "--part".to_owned(),
        format!("{k}/{n}"),
        "-o".to_owned(),
        part_file(parts, k, n).display().to_string(),
    ];
    if resume {
        args.push("--resume".to_owned());
    }
    args
}

#[test]
fn task_script_runs_the_part_given_by_each_engines_variables() {
    let (dir, parts) = with_parts("task");
    let p = parts.to_str().unwrap();
    let base = [("LUMEN_SCENE", "cover"), ("LUMEN_PARTS_DIR", p)];
    let run = |vars: &[(&str, &str)]| {
        let all: Vec<(&str, &str)> = base.iter().chain(vars).copied().collect();
        let out = run_script("task.sh", &dir, &all);
        assert!(out.status.success(), "{vars:?}: {}", text(&out.stderr));
        lines(&out)
    };

    // By hand, with options for lumen: split at spaces, never globbed.
    let mut want = task_args(&parts, 2, 3, false);
    want.extend(["--spp", "64", "--seed", "*"].map(str::to_owned));
    let got = run(&[
        ("LUMEN_TASK_INDEX", "2"),
        ("LUMEN_TASK_COUNT", "3"),
        ("LUMEN_ARGS", " --spp  64 --seed *"),
    ]);
    assert_eq!(got, want);

    // Kubernetes: the index is JOB_COMPLETION_INDEX, the count LUMEN_PARTS
    // or LUMEN_TASK_COUNT.
    assert_eq!(
        run(&[("JOB_COMPLETION_INDEX", "1"), ("LUMEN_PARTS", "2")]),
        task_args(&parts, 1, 2, false)
    );
    assert_eq!(
        run(&[("JOB_COMPLETION_INDEX", "0"), ("LUMEN_TASK_COUNT", "1")]),
        task_args(&parts, 0, 1, false)
    );
    // Slurm: SLURM_ARRAY_TASK_ID of SLURM_ARRAY_TASK_COUNT...
    assert_eq!(
        run(&[
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_COUNT", "4")
        ]),
        task_args(&parts, 3, 4, false)
    );
    // ...but LUMEN_TASK_COUNT first: an array resubmitted for one failed
    // index (--array=3) has a task count of 1.
    assert_eq!(
        run(&[
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_COUNT", "1"),
            ("LUMEN_TASK_COUNT", "4")
        ]),
        task_args(&parts, 3, 4, false)
    );
    // LUMEN_TASK_INDEX before the engines' variables; an empty variable is
    // as good as unset.
    assert_eq!(
        run(&[
            ("LUMEN_TASK_INDEX", "0"),
            ("SLURM_ARRAY_TASK_ID", "1"),
            ("JOB_COMPLETION_INDEX", "2"),
            ("LUMEN_TASK_COUNT", "3")
        ]),
        task_args(&parts, 0, 3, false)
    );
    assert_eq!(
        run(&[
            ("LUMEN_TASK_INDEX", ""),
            ("SLURM_ARRAY_TASK_ID", ""),
            ("JOB_COMPLETION_INDEX", "2"),
            ("LUMEN_TASK_COUNT", "3")
        ]),
        task_args(&parts, 2, 3, false)
    );

    // A task run again (requeued, or the whole array resubmitted) continues
    // its part file, which is its checkpoint, or finds the part complete:
    // --resume whenever the part file is there. A file named like the
    // checkpoint of a whole render is not looked at.
    let vars = [("LUMEN_TASK_INDEX", "1"), ("LUMEN_TASK_COUNT", "2")];
    fs::write(parts.join("part-1.lumen-ckpt"), "").unwrap();
    assert_eq!(run(&vars), task_args(&parts, 1, 2, false));
    fs::remove_file(parts.join("part-1.lumen-ckpt")).unwrap();
    fs::write(parts.join("part-1.lumen-part"), "").unwrap();
    assert_eq!(run(&vars), task_args(&parts, 1, 2, true));
    // Another part's files do not count.
    assert_eq!(
        run(&[("LUMEN_TASK_INDEX", "0"), ("LUMEN_TASK_COUNT", "2")]),
        task_args(&parts, 0, 2, false)
    );

    // lumen's exit status is the task's (130: stopped by a signal, its part
    // file saved), so the engine sees the failure.
    let mut all = base.to_vec();
    all.extend([
        ("LUMEN_TASK_INDEX", "0"),
        ("LUMEN_TASK_COUNT", "2"),
        ("STUB_STATUS", "130"),
    ]);
    assert_eq!(run_script("task.sh", &dir, &all).status.code(), Some(130));
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn task_script_refuses_missing_or_wrong_settings_without_running_lumen() {
    let (dir, parts) = with_parts("task-refusals");
    let p = parts.to_str().unwrap();
    let missing = dir.join("missing");
    let m = missing.to_str().unwrap();
    let ok = [
        ("LUMEN_SCENE", "cover"),
        ("LUMEN_PARTS_DIR", p),
        ("LUMEN_TASK_INDEX", "1"),
        ("LUMEN_TASK_COUNT", "2"),
    ];
    // Each case: variables that replace or remove (empty) those of `ok`, and
    // what the message must name.
    let cases: &[(&[(&str, &str)], &str)] = &[
        (&[("LUMEN_TASK_INDEX", "")], "no task index"),
        (&[("LUMEN_TASK_COUNT", "")], "no task count"),
        (&[("LUMEN_TASK_INDEX", "2")], "task index 2"),
        (&[("LUMEN_TASK_INDEX", "7")], "not below the task count 2"),
        (&[("LUMEN_TASK_COUNT", "0")], "at least one part"),
        (&[("LUMEN_TASK_INDEX", "-1")], "LUMEN_TASK_INDEX is '-1'"),
        (&[("LUMEN_TASK_INDEX", "1.0")], "not a whole number"),
        (&[("LUMEN_TASK_INDEX", "01")], "LUMEN_TASK_INDEX is '01'"),
        (&[("LUMEN_TASK_INDEX", " 1")], "not a whole number"),
        (&[("LUMEN_TASK_COUNT", "two")], "LUMEN_TASK_COUNT is 'two'"),
        (
            &[("LUMEN_TASK_COUNT", "99999999999999999999")],
            "not a whole number",
        ),
        (
            &[("LUMEN_TASK_INDEX", ""), ("JOB_COMPLETION_INDEX", "x")],
            "JOB_COMPLETION_INDEX is 'x'",
        ),
        (
            &[("LUMEN_TASK_COUNT", ""), ("SLURM_ARRAY_TASK_COUNT", "1")],
            "task count 1 (SLURM_ARRAY_TASK_COUNT)",
        ),
        (&[("LUMEN_SCENE", "")], "LUMEN_SCENE is not set"),
        (&[("LUMEN_PARTS_DIR", "")], "LUMEN_PARTS_DIR is not set"),
        (&[("LUMEN_PARTS_DIR", m)], "is not a directory"),
        (&[("LUMEN_ARGS", "--spp 4 -o x.png")], "LUMEN_ARGS holds -o"),
        (
            &[("LUMEN_ARGS", "--part=0/1")],
            "LUMEN_ARGS holds --part=0/1",
        ),
        (&[("LUMEN_ARGS", "--resume")], "LUMEN_ARGS holds --resume"),
        (
            &[("LUMEN_ARGS", "--checkpoint c")],
            "holds --checkpoint: a part file is its own checkpoint",
        ),
        (&[("LUMEN_ARGS", "--checkpoint=c")], "holds --checkpoint=c"),
    ];
    for (changes, message) in cases {
        let mut vars: BTreeMap<&str, &str> = ok.into_iter().collect();
        vars.extend(changes.iter().copied());
        let vars: Vec<(&str, &str)> = vars.into_iter().collect();
        let out = run_script("task.sh", &dir, &vars);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{changes:?}: {err}");
        assert!(
            err.starts_with("lumen-task: error: ") && err.contains(message),
            "{changes:?}: expected {message:?} in {err:?}"
        );
        assert!(!dir.join("ran").exists(), "{changes:?} ran lumen");
        assert!(out.stdout.is_empty());
    }
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn merge_script_names_missing_parts_and_merges_a_complete_set_in_index_order() {
    let (dir, parts) = with_parts("merge");
    let p = parts.to_str().unwrap();
    let out_png = dir.join("final.png");
    let o = out_png.to_str().unwrap();
    let part = |k: u32| part_file(&parts, k, 4);
    for k in [0, 2, 10] {
        fs::write(part(k), "").unwrap();
    }
    let vars = [
        ("LUMEN_PARTS_DIR", p),
        ("LUMEN_TASK_COUNT", "4"),
        ("LUMEN_OUT", o),
    ];

    // Parts 1 and 3 missing (10 is not one of the 4): refused, naming them in
    // the form `sbatch --array` takes.
    let out = run_script("merge.sh", &dir, &vars);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("no part file for index 1,3 of 4"),
        "{}",
        text(&out.stderr)
    );
    assert!(!dir.join("ran").exists());

    // A preview merges what is there.
    let mut partial = vars.to_vec();
    partial.push(("LUMEN_MERGE_ARGS", "--partial"));
    let out = run_script("merge.sh", &dir, &partial);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let path = |k| part(k).display().to_string();
    assert_eq!(
        lines(&out),
        ["merge", &path(0), &path(2), "-o", o, "--partial"]
    );

    for k in [1, 3] {
        fs::write(part(k), "").unwrap();
    }
    let out = run_script("merge.sh", &dir, &vars);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(
        lines(&out),
        ["merge", &path(0), &path(1), &path(2), &path(3), "-o", o]
    );

    let out = run_script("merge.sh", &dir, &vars[..1]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("LUMEN_OUT is not set"));
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_scripts_split_by_tiles_with_the_real_lumen_and_merge_to_the_bit() {
    // The Kubernetes path: the index set as JOB_COMPLETION_INDEX, the
    // split given in LUMEN_ARGS.
    let (dir, parts) = with_parts("tiles");
    let args = "--width 40 --spp 6 --seed 3 --split tiles";
    for k in [2, 0, 1] {
        let out = clean_command("sh")
            .arg(deploy_dir().join("task.sh"))
            .env("LUMEN_BIN", LUMEN)
            .env("JOB_COMPLETION_INDEX", k.to_string())
            .env("LUMEN_PARTS", "3")
            .env("LUMEN_SCENE", "cover")
            .env("LUMEN_PARTS_DIR", &parts)
            .env("LUMEN_ARGS", args)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", text(&out.stderr));
        assert!(
            text(&out.stderr).contains(&format!("part {k}/3 (tiles): pixels 0,")),
            "{}",
            text(&out.stderr)
        );
    }
    let merged = dir.join("final.pfm");
    let out = clean_command("sh")
        .arg(deploy_dir().join("merge.sh"))
        .env("LUMEN_BIN", LUMEN)
        .env("LUMEN_TASK_COUNT", "3")
        .env("LUMEN_PARTS_DIR", &parts)
        .env("LUMEN_OUT", &merged)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    let one = dir.join("one.pfm");
    let out = Command::new(LUMEN)
        .args([
            "render", "cover", "--width", "40", "--spp", "6", "--seed", "3", "-o",
        ])
        .arg(&one)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(fs::read(&merged).unwrap() == fs::read(&one).unwrap());
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn submit_script_checks_its_arguments_before_submitting() {
    let dir = fresh_dir("submit");
    let submit = deploy_dir().join("slurm/submit.sh");
    let run = |args: &[&str]| {
        clean_command("/bin/sh")
            .arg(&submit)
            .args(args)
            .current_dir(&dir)
            // No sbatch on the path: nothing may be submitted. (The checks
            // need nothing but the shell.)
            .env("PATH", "/nonexistent")
            .output()
            .unwrap()
    };
    let out = run(&["cover", "parts", "4"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).starts_with("usage: "));
    for n in ["0", "x", "-2", "08"] {
        let out = run(&["cover", "parts", n, "out.png"]);
        assert_eq!(out.status.code(), Some(2), "{n}");
        assert!(text(&out.stderr).contains("not a number of parts"), "{n}");
    }
    let out = run(&["cover", "parts", "4", "out.png", "--seed", "1 2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("holds a space"));
    fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------
// A one-node Slurm cluster.

/// Finds a program on PATH or in the sbin directories, which a non-login
/// PATH may lack.
fn find_program(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .chain(["/usr/sbin", "/usr/local/sbin", "/sbin"].map(PathBuf::from))
        .map(|dir| dir.join(name))
        .find(|p| p.is_file())
}

/// Returns why a Slurm cluster cannot be started here, if it cannot.
fn slurm_missing() -> Option<String> {
    let missing: Vec<&str> = [
        "munged",
        "mungekey",
        "slurmctld",
        "slurmd",
        "sbatch",
        "squeue",
        "sinfo",
        "scontrol",
    ]
    .into_iter()
    .filter(|p| find_program(p).is_none())
    .collect();
    if !missing.is_empty() {
        return Some(format!(
            "not installed: {} (Debian: apt-get install slurm-wlm munge)",
            missing.join(", ")
        ));
    }
    // SAFETY: geteuid has no preconditions and cannot fail.
    if unsafe { libc::geteuid() } != 0 {
        return Some("slurmd must run as root to start jobs".to_owned());
    }
    None
}

/// Whether the Slurm tests may be skipped; panics when they may not.
fn skip_without_slurm(test: &str) -> bool {
    let Some(why) = slurm_missing() else {
        return false;
    };
    if std::env::var("LUMEN_REQUIRE_SLURM").is_ok_and(|v| v == "1") {
        panic!("{test}: Slurm is required (LUMEN_REQUIRE_SLURM=1) but {why}");
    }
    // Straight to stderr, past the test harness's capture, so that the skip
    // shows in a passing run.
    let _ = writeln!(
        std::io::stderr(),
        "{test}: SKIPPED, no Slurm cluster can be started: {why}"
    );
    true
}

/// A TCP port free at the time of asking.
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

fn command_output(program: &str, args: &[&str]) -> String {
    let out = Command::new(program).args(args).output().unwrap();
    assert!(out.status.success(), "{program} {args:?} failed");
    text(&out.stdout).trim().to_owned()
}

/// A one-node Slurm cluster on this machine, with its own munge daemon, key,
/// configuration, ports and state under a fresh directory, so that it neither
/// needs nor disturbs a Slurm or munge set up on the machine. Shut down and
/// removed on drop (kept, with its logs printed, when the test failed).
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
    daemons: Vec<(&'static str, Child)>,
}

impl Cluster {
    fn start() -> Cluster {
        let dir = fresh_dir("slurm");
        let host = command_output("hostname", &["-s"]);
        let cpus = command_output("nproc", &[]);
        let d = dir.display();
        let mut cluster = Cluster {
            conf: dir.join("slurm.conf"),
            dir: dir.clone(),
            daemons: Vec::new(),
        };

        // munge authenticates every message between the Slurm commands and
        // daemons. A private daemon on its own socket and key
        // (AuthInfo=socket=... below) rather than the machine's.
        let key = dir.join("munge.key");
        let status = Command::new(find_program("mungekey").unwrap())
            .arg("--create")
            .arg(format!("--keyfile={}", key.display()))
            .status()
            .unwrap();
        assert!(status.success(), "mungekey failed");
        let socket = dir.join("munge.sock");
        cluster.spawn(
            "munged",
            &[
                "--foreground",
                "--force",
                &format!("--socket={}", socket.display()),
                &format!("--key-file={}", key.display()),
                &format!("--log-file={d}/munged.log"),
                &format!("--pid-file={d}/munged.pid"),
                &format!("--seed-file={d}/munged.seed"),
            ],
        );
        wait_for("munged's socket", Duration::from_secs(10), || {
            socket.exists()
        });

        for sub in ["state", "spool"] {
            fs::create_dir(dir.join(sub)).unwrap();
        }
        // An empty plugin stack: the machine's /etc/slurm/plugstack.conf is
        // not this cluster's.
        fs::write(dir.join("plugstack.conf"), "").unwrap();
        let (ctld_port, slurmd_port) = (free_port(), free_port());
        let conf = format!(
            "\
ClusterName=lumentest
SlurmctldHost={host}(127.0.0.1)
SlurmctldPort={ctld_port}
SlurmdPort={slurmd_port}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket={socket}
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/slurmctld.log
SlurmdLogFile={d}/slurmd.log
PlugStackConfig={d}/plugstack.conf
NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN
PartitionName=debug Nodes={host} Default=YES MaxTime=INFINITE State=UP
",
            socket = socket.display()
        );
        fs::write(&cluster.conf, conf).unwrap();

        // In the foreground (-D) so that they stay this process's children,
        // to be killed on drop whatever happened. -i: ignore any state left.
        let conf = cluster.conf.display().to_string();
        cluster.spawn("slurmctld", &["-D", "-i", "-f", &conf]);
        cluster.spawn("slurmd", &["-D", "-f", &conf]);
        wait_for("the node to be idle", Duration::from_secs(30), || {
            let out = cluster
                .command("sinfo")
                .args(["-h", "-n", &host, "-o", "%T"])
                .output()
                .unwrap();
            text(&out.stdout).trim() == "idle"
        });
        cluster
    }

    fn spawn(&mut self, name: &'static str, args: &[&str]) {
        let log = fs::File::create(self.dir.join(format!("{name}.out"))).unwrap();
        let mut cmd = Command::new(find_program(name).unwrap());
        cmd.args(args)
            .stdin(Stdio::null())
            .stdout(log.try_clone().unwrap())
            .stderr(log);
        // Should the test process die without dropping the cluster (killed
        // by a timeout, say), the daemons die with it rather than linger.
        #[cfg(target_os = "linux")]
        {
            use std::os::unix::process::CommandExt;
            // SAFETY: prctl is async-signal-safe, as code between fork and
            // exec must be; it touches no memory of the parent.
            unsafe {
                cmd.pre_exec(|| {
                    libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
                    Ok(())
                });
            }
        }
        let child = cmd.spawn().unwrap_or_else(|e| panic!("{name}: {e}"));
        self.daemons.push((name, child));
    }

    /// A Slurm command addressed to this cluster.
    fn command(&self, program: &str) -> Command {
        self.script(find_program(program).unwrap())
    }

    /// A script that runs Slurm commands, addressed to this cluster.
    fn script(&self, path: impl AsRef<OsStr>) -> Command {
        let mut cmd = clean_command(path);
        cmd.env("SLURM_CONF", &self.conf);
        cmd
    }

    /// Runs a Slurm command that must succeed; returns its stdout.
    fn run(&self, program: &str, args: &[&str]) -> String {
        let out = self.command(program).args(args).output().unwrap();
        assert!(
            out.status.success(),
            "{program} {args:?}: {}",
            text(&out.stderr)
        );
        text(&out.stdout)
    }

    /// The jobs (or array tasks) among `ids` still known to the controller
    /// and not finished, one `ID STATE REASON` line each.
    fn queued(&self, ids: &str) -> Vec<String> {
        let out = self
            .command("squeue")
            .args(["-h", "-j", ids, "-o", "%i %T %r"])
            .output()
            .unwrap();
        // Jobs long finished are forgotten: squeue then fails with "Invalid
        // job id specified".
        text(&out.stdout).lines().map(str::to_owned).collect()
    }

    /// Waits until no job of `ids` (comma-separated) is pending or running.
    fn wait_finished(&self, ids: &str, timeout: Duration) {
        wait_for(&format!("jobs {ids} to finish"), timeout, || {
            self.queued(ids).is_empty()
        });
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = self
            .command("scontrol")
            .arg("shutdown")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status();
        let deadline = Instant::now() + Duration::from_secs(10);
        // The Slurm daemons first (they stop on `scontrol shutdown`), munged
        // last: they need it until they are gone.
        for (name, child) in self.daemons.iter_mut().rev() {
            if *name == "munged" {
                // SAFETY: kill has no memory-safety preconditions; the pid is
                // that of our own child, not yet waited for.
                unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
            }
            while child.try_wait().ok().flatten().is_none() && Instant::now() < deadline {
                sleep(Duration::from_millis(100));
            }
            if child.try_wait().ok().flatten().is_none() {
                let _ = child.kill();
                let _ = child.wait();
            }
        }
        if std::thread::panicking() {
            eprintln!("Slurm cluster kept in {}", self.dir.display());
            for log in ["slurmctld.log", "slurmd.log"] {
                let text = fs::read_to_string(self.dir.join(log)).unwrap_or_default();
                let tail: Vec<&str> = text.lines().rev().take(30).collect();
                eprintln!("--- {log} (end) ---");
                for line in tail.into_iter().rev() {
                    eprintln!("{line}");
                }
            }
        } else {
            let _ = fs::remove_dir_all(&self.dir);
        }
    }
}

fn wait_for(what: &str, timeout: Duration, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(
            start.elapsed() < timeout,
            "timed out after {timeout:?} waiting for {what}"
        );
        sleep(Duration::from_millis(200));
    }
}

/// `deploy/slurm/submit.sh cover PARTS N OUT OPTIONS...` on `cluster`, with
/// `LUMEN_BIN` the lumen under test and `vars`; returns the ids of the array
/// and the merge.
fn submit(
    cluster: &Cluster,
    (parts, n, out): (&Path, u32, &Path),
    options: &[&str],
    vars: &[(&str, &str)],
) -> (String, String) {
    let submitted = cluster
        .script(deploy_dir().join("slurm/submit.sh"))
        .arg("cover")
        .arg(parts)
        .arg(n.to_string())
        .arg(out)
        .args(options)
        .env("LUMEN_BIN", LUMEN)
        .envs(vars.iter().copied())
        .current_dir(parts.parent().unwrap())
        .output()
        .unwrap();
    assert!(
        submitted.status.success(),
        "submit.sh: {}",
        text(&submitted.stderr)
    );
    // `render=ID` and `merge=ID`.
    let ids: BTreeMap<String, String> = text(&submitted.stdout)
        .lines()
        .filter_map(|l| l.split_once('='))
        .map(|(k, v)| (k.to_owned(), v.to_owned()))
        .collect();
    (ids["render"].clone(), ids["merge"].clone())
}

/// The ids of the running `lumen render` processes whose command line holds
/// `--part PART` and `-o OUTPUT`.
fn lumen_processes(part: &str, output: &Path) -> Vec<libc::pid_t> {
    let want_part = format!("\0--part\0{part}\0");
    let want_out = format!("\0-o\0{}\0", output.display());
    let Ok(entries) = fs::read_dir("/proc") else {
        return Vec::new();
    };
    entries
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse::<libc::pid_t>().ok())
        .filter(|pid| {
            let Ok(cmdline) = fs::read(format!("/proc/{pid}/cmdline")) else {
                return false;
            };
            let cmdline = format!("\0{}", text(&cmdline));
            cmdline.contains("\0render\0")
                && cmdline.contains(&want_part)
                && cmdline.contains(&want_out)
        })
        .collect()
}

/// The task id (`ARRAY_K`) of every task of `array` Slurm says is running.
fn running_tasks(cluster: &Cluster, array: &str) -> Vec<String> {
    cluster
        .queued(array)
        .iter()
        .filter(|l| l.contains(" RUNNING "))
        .filter_map(|l| l.split(' ').next().map(str::to_owned))
        .collect()
}

fn task_index(task: &str) -> u32 {
    task.rsplit('_').next().unwrap().parse().unwrap()
}

#[test]
fn slurm_array_renders_every_part_through_a_requeue_and_a_failure_then_merges() {
    if skip_without_slurm(
        "slurm_array_renders_every_part_through_a_requeue_and_a_failure_then_merges",
    ) {
        return;
    }
    let started = Instant::now();
    let cluster = Cluster::start();
    let work = cluster.dir.join("work");
    let parts = work.join("parts");
    fs::create_dir_all(&work).unwrap();
    // A few seconds a part on the one CPU Slurm gives each task, so that a
    // task is still running when it is requeued or killed.
    let options: &[&str] = &["--width", "160", "--spp", "2048", "--seed", "3"];
    let out = work.join("final.pfm");
    const N: u32 = 4;
    // The part whose render is killed half-way, as by a lost node or the
    // out-of-memory killer: the task fails and Slurm does not requeue it.
    const KILLED: u32 = 3;
    let part = |k: u32| part_file(&parts, k, N);
    let read_merge_log =
        |merge: &str| fs::read_to_string(parts.join(format!("logs/merge-{merge}.out"))).unwrap();
    let task_log = |render: &str, k: u32| {
        fs::read_to_string(parts.join(format!("logs/render-{render}_{k}.out"))).unwrap_or_default()
    };

    let (render, merge) = submit(&cluster, (&parts, N, &out), options, &[]);

    // Requeue a task while its render runs, once it has written its part
    // file (its first pass), as a node failure or preemption would: lumen is
    // sent SIGTERM, saves the part and stops. Release it at once rather than
    // after Slurm's requeue delay.
    let mut victim = String::new();
    wait_for("a task half-way", Duration::from_secs(20), || {
        let found = running_tasks(&cluster, &render).into_iter().find(|t| {
            let k = task_index(t);
            k != KILLED && part(k).exists()
        });
        found.map(|t| victim = t).is_some()
    });
    let victim_k = task_index(&victim);
    cluster.run("scontrol", &["requeue", &victim]);
    wait_for("the requeued task to wait", Duration::from_secs(20), || {
        cluster
            .queued(&victim)
            .first()
            .is_some_and(|l| l.contains(" PENDING "))
    });
    cluster.run(
        "scontrol",
        &["update", &format!("jobid={victim}"), "StartTime=now"],
    );

    // Kill part KILLED's lumen half-way: its part file holds some passes.
    let killed_part = format!("{KILLED}/{N}");
    let mut pids = Vec::new();
    wait_for("part 3 half-way", Duration::from_secs(30), || {
        if !part(KILLED).exists() {
            return false;
        }
        pids = lumen_processes(&killed_part, &part(KILLED));
        !pids.is_empty()
    });
    for &pid in &pids {
        // SAFETY: kill has no memory-safety preconditions.
        unsafe { libc::kill(pid, libc::SIGKILL) };
    }

    // The merge runs once every task has ended, the failed one too.
    cluster.wait_finished(&format!("{render},{merge}"), Duration::from_secs(45));
    let logs: Vec<String> = fs::read_dir(parts.join("logs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        logs.len(),
        N as usize + 1,
        "{logs:?}: one per task and the merge's"
    );
    // The requeued task ran twice, the second time resuming its part file.
    let log = task_log(&render, victim_k);
    assert_eq!(
        log.matches(&format!("lumen-task: part {victim_k}/{N} of cover"))
            .count(),
        2,
        "{log}"
    );
    assert!(log.contains(" (resuming) "), "{log}");
    // The merge found the killed task's part unfinished and wrote nothing.
    let merge_log = read_merge_log(&merge);
    assert!(merge_log.contains("part unfinished"), "{merge_log}");
    assert!(!out.exists());

    // The way docs/distributed.md gives to rerun a failed index: the same
    // command with LUMEN_ARRAY. The one-task array must resume part KILLED
    // of N, not render part 0 of 1, and a new merge follows it.
    let again = KILLED.to_string();
    let (rerun, merge) = submit(
        &cluster,
        (&parts, N, &out),
        options,
        &[("LUMEN_ARRAY", &again)],
    );
    cluster.wait_finished(&format!("{rerun},{merge}"), Duration::from_secs(30));
    let log = task_log(&rerun, KILLED);
    assert!(
        log.contains(&format!("part {KILLED}/{N} of cover")) && log.contains(" (resuming) "),
        "{log}"
    );
    let merge_log = read_merge_log(&merge);
    let merged = fs::read(&out).unwrap_or_else(|e| panic!("{e}: {merge_log}"));

    // The merged image is the one-machine render's, bit for bit.
    let reference = lumen_process::reference(&work, &[&["render", "cover"], options].concat());
    assert!(
        merged == reference,
        "the merged image differs from the one-machine render: {merge_log}"
    );
    eprintln!("Slurm renders and merges took {:?}", started.elapsed());
}
