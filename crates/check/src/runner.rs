//! The runner: the matrix run the way Mesa's deqp-runner runs dEQP. Cases go to worker
//! processes in batches (a scene at one resolution and format shares a renderer and its forward
//! reference), `jobs` workers at a time. A worker is a fresh process per batch, so a driver's
//! memory growth is bounded by one batch, and a crash or a lost device fails only the case it
//! had in flight (`Crash`) before the rest of its batch goes to a new worker. A case that runs
//! past the timeout has its worker killed (`Timeout`). Results stream to `results.csv` as they
//! arrive; a baseline turns known failures into `ExpectedFail` and reports unexpected passes;
//! every unexpected failure is rerun once, and one that passes then is a `Flake`.
//!
//! Workers speak one line per event on stdout: `start <scene/case>`, `result <Record JSON>`,
//! `peak <MiB>`. Their stderr goes to a log file per worker under `<out>/workers/`, which a crash
//! report quotes.

use crate::lists::{Baseline, Patterns, Status};
use crate::report::{self, Record, RunReport, WorkerInfo};
use serde_json::Value;
use std::collections::{HashMap, VecDeque};
use std::ffi::OsString;
use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// How to start a worker and what to do with its results.
pub struct RunnerOptions {
    /// The worker's program and arguments; the runner appends `--caselist FILE`.
    pub program: PathBuf,
    pub args: Vec<OsString>,
    /// Environment variables the workers must not see (the validation layer's muting
    /// settings), and those they get.
    pub env_remove: Vec<String>,
    pub env_set: Vec<(String, OsString)>,
    pub jobs: usize,
    /// A case's longest run; a group's first case includes the group's setup.
    pub timeout: Duration,
    /// Stop after this many failing cases (regressions, crashes, timeouts).
    pub max_fails: Option<usize>,
    /// At most this many cases per worker process.
    pub cases_per_worker: usize,
    pub baseline: Baseline,
    pub flakes: Patterns,
    /// Where `results.csv`, `failures.csv`, the batches' case lists and the workers' logs go.
    pub out: PathBuf,
    /// Set from outside (a SIGINT or SIGTERM handler) to stop: workers are killed, what
    /// finished is kept.
    pub stop: &'static AtomicBool,
    /// A progress line this often (cases done of total, failing so far, elapsed).
    pub progress_every: Duration,
}

/// A case to run, in plan order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlannedCase {
    pub scene: String,
    pub case: String,
    /// Cases with one group share a worker's renderer (scene, resolution, format).
    pub group: String,
    /// Rough cost, for running the dearest batches first.
    pub pixels: u64,
}

impl PlannedCase {
    pub fn full_name(&self) -> String {
        format!("{}/{}", self.scene, self.case)
    }
}

/// The batches of `cases`: consecutive cases of one group, at most `size` each, dearest first
/// (so that the last worker to finish is not the one that started the largest frame last).
pub fn batches(cases: &[PlannedCase], size: usize) -> Vec<Vec<PlannedCase>> {
    let mut out: Vec<Vec<PlannedCase>> = Vec::new();
    for case in cases {
        match out.last_mut() {
            Some(b) if b[0].group == case.group && b.len() < size.max(1) => b.push(case.clone()),
            _ => out.push(vec![case.clone()]),
        }
    }
    let cost = |b: &Vec<PlannedCase>| b.iter().map(|c| c.pixels + 10_000).sum::<u64>();
    out.sort_by_key(|b| std::cmp::Reverse(cost(b)));
    out
}

/// A worker's raw record with the baseline and flake patterns applied.
pub fn classify(mut r: Record, baseline: &Baseline, flakes: &Patterns) -> Record {
    let name = r.full_name();
    let expected = baseline.expected.get(&name).copied();
    let why = r.reason.clone().unwrap_or_default();
    match (r.status, expected) {
        (Status::Pass, Some(e)) => {
            r.status = Status::UnexpectedPass;
            r.reason = Some(format!(
                "the baseline expects {e}, and it passed: remove its line"
            ));
        }
        (s, Some(e)) if s == e => {
            r.status = Status::ExpectedFail;
            r.reason = Some(format!("expected {e} (baseline): {why}"));
        }
        (s, _) if s.is_failure() && s != Status::ValidationLayerMuted && flakes.matches(&name) => {
            r.status = Status::Flake;
            r.reason = Some(format!("flake (matches --flakes): {s}: {why}"));
        }
        _ => {}
    }
    r
}

/// A record for a case its worker never reported: it crashed or timed out with it in flight.
fn lost(case: &PlannedCase, status: Status, reason: String, seconds: f64) -> Record {
    Record {
        scene: case.scene.clone(),
        name: case.case.clone(),
        status,
        seconds,
        failure_type: Some(status.name().to_lowercase()),
        details: format!("{reason}\n"),
        reason: Some(reason),
        data: Value::Null,
    }
}

/// The exit code of a worker that has no device or no validation layer: the run cannot go on.
pub const NO_DEVICE_EXIT: i32 = 3;

/// A record as a log line: `Status scene/case: reason`.
fn line(r: &Record) -> String {
    format!(
        "{} {}: {}",
        r.status,
        r.full_name(),
        r.reason.as_deref().unwrap_or("")
    )
}

/// What a worker thread tells the runner.
enum Message {
    Record(Record),
    Worker(WorkerInfo),
}

/// The batches still to run, shared by the worker threads.
struct Queue {
    batches: Mutex<VecDeque<Vec<PlannedCase>>>,
    next_id: AtomicUsize,
}

/// Runs `cases` (plan order) and fills `report` with every record in plan order (device rows,
/// the canaries and teardowns, one per name, after them) and the workers that ran. `skipped`
/// (cases the `--skips` patterns matched) are reported as they are.
///
/// # Errors
/// `results.csv`, `failures.csv` or a worker's files cannot be written, or a worker cannot be
/// started.
pub fn run(
    cases: &[PlannedCase],
    skipped: Vec<Record>,
    options: &RunnerOptions,
    report: &mut RunReport,
) -> RunResult<()> {
    let start = Instant::now();
    std::fs::create_dir_all(options.out.join("workers"))?;
    let mut run = Run {
        options,
        results: std::fs::File::create(options.out.join("results.csv"))?,
        device: Vec::new(),
        failing: 0,
        done: 0,
        total: cases.len(),
        start,
        halt: Arc::new(AtomicBool::new(false)),
        workers: Vec::new(),
        queue_ids: AtomicUsize::new(0),
    };
    run.results.write_all(b"# case,status,seconds\n")?;
    for r in &skipped {
        run.results.write_all(report::results_line(r).as_bytes())?;
    }
    let mut first = run.pass(cases, false, |r| {
        classify(r, &options.baseline, &options.flakes)
    })?;
    // Every unexpected failure once more: a pass on the rerun is a flake.
    let rerun: Vec<PlannedCase> = cases
        .iter()
        .filter(|c| {
            first
                .get(&c.full_name())
                .is_some_and(|r| r.status.is_failure() && r.status != Status::ValidationLayerMuted)
        })
        .cloned()
        .collect();
    if !rerun.is_empty() && !run.halted() {
        eprintln!(
            "histencil check: rerunning {} failing case(s) once, to tell flakes from regressions",
            rerun.len()
        );
        run.total += rerun.len();
        let again = run.pass(&rerun, true, |r| r)?;
        for (name, second) in again {
            let Some(r) = first.get_mut(&name) else {
                continue;
            };
            if second.status == Status::Pass {
                r.reason = Some(format!(
                    "flake: {} on its first run, passed on its rerun: {}",
                    r.status,
                    r.reason.clone().unwrap_or_default()
                ));
                r.status = Status::Flake;
                run.failing = run.failing.saturating_sub(1);
            } else {
                r.details.push_str(&format!(
                    "rerun: {}: {}\n",
                    second.status,
                    second.reason.unwrap_or_default()
                ));
            }
        }
    }
    let order: HashMap<String, usize> = cases
        .iter()
        .enumerate()
        .map(|(i, c)| (c.full_name(), i))
        .collect();
    let mut records: Vec<Record> = skipped;
    records.extend(first.into_values());
    records.sort_by_key(|r| order.get(&r.full_name()).copied().unwrap_or(usize::MAX));
    records.append(&mut run.device);
    if run.halt.load(Ordering::SeqCst) {
        report.incomplete = Some(format!(
            "stopped after {} failing cases (--max-fails)",
            run.failing
        ));
    } else if options.stop.load(Ordering::SeqCst) {
        report.incomplete = Some("interrupted by a signal: the reports hold what finished".into());
    }
    report.records = records;
    report.workers = std::mem::take(&mut run.workers);
    report.seconds = start.elapsed().as_secs_f64();
    // The final statuses, flakes included, replace the streamed first-pass lines.
    let mut text = String::from("# case,status,seconds\n");
    for r in &report.records {
        text.push_str(&report::results_line(r));
    }
    histencil_vk::write_atomically(&options.out.join("results.csv"), text.as_bytes())?;
    histencil_vk::write_atomically(
        &options.out.join("failures.csv"),
        report::failures_csv(report).as_bytes(),
    )?;
    Ok(())
}

/// One run's state on the runner's thread.
struct Run<'a> {
    options: &'a RunnerOptions,
    results: std::fs::File,
    /// Device rows (canaries, teardowns), one per name: the worst any worker reported.
    device: Vec<Record>,
    failing: usize,
    done: usize,
    total: usize,
    start: Instant,
    /// Set when `--max-fails` is reached.
    halt: Arc<AtomicBool>,
    workers: Vec<WorkerInfo>,
    queue_ids: AtomicUsize,
}

impl Run<'_> {
    fn halted(&self) -> bool {
        self.halt.load(Ordering::SeqCst) || self.options.stop.load(Ordering::SeqCst)
    }

    /// Runs `cases` on the workers; returns each case's record after `classify`. A rerun's
    /// failures are not counted again (nor towards `--max-fails`).
    fn pass(
        &mut self,
        cases: &[PlannedCase],
        rerun: bool,
        classify: impl Fn(Record) -> Record,
    ) -> RunResult<HashMap<String, Record>> {
        let queue = Queue {
            batches: Mutex::new(batches(cases, self.options.cases_per_worker).into()),
            next_id: AtomicUsize::new(self.queue_ids.load(Ordering::SeqCst)),
        };
        let (tx, rx) = mpsc::channel();
        let mut records = HashMap::new();
        let mut last_progress = Instant::now();
        let halt = self.halt.clone();
        let started = std::thread::scope(|scope| -> RunResult<()> {
            let mut handles = Vec::new();
            for _ in 0..self.options.jobs.max(1) {
                let tx = tx.clone();
                let (queue, options, halt) = (&queue, self.options, &*halt);
                handles.push(scope.spawn(move || work(queue, options, halt, &tx)));
            }
            drop(tx);
            let mut written = Ok(());
            loop {
                match rx.recv_timeout(Duration::from_millis(200)) {
                    Ok(Message::Record(r)) if r.scene == "device" => {
                        // A failing device row (a muted canary, leaks at teardown) is streamed
                        // at once: a killed job's results.csv must not read all green.
                        if r.status.is_failure() && written.is_ok() {
                            written = self.results.write_all(report::results_line(&r).as_bytes());
                        }
                        self.fold_device(r);
                    }
                    Ok(Message::Record(r)) => {
                        let r = classify(r);
                        self.done += 1;
                        if rerun {
                            // The final results.csv has the verdict of both runs.
                            eprintln!("rerun: {}", line(&r));
                        } else {
                            if written.is_ok() {
                                written =
                                    self.results.write_all(report::results_line(&r).as_bytes());
                            }
                            self.failed(&r);
                        }
                        records.insert(r.full_name(), r);
                    }
                    Ok(Message::Worker(w)) => self.workers.push(w),
                    Err(mpsc::RecvTimeoutError::Timeout) => {}
                    Err(mpsc::RecvTimeoutError::Disconnected) => break,
                }
                if written.is_err() {
                    // Nothing more can be streamed: stop the workers, then say why.
                    self.halt.store(true, Ordering::SeqCst);
                }
                if last_progress.elapsed() >= self.options.progress_every {
                    last_progress = Instant::now();
                    eprintln!(
                        "histencil check: {}/{} cases, {} failing, {:.0} s",
                        self.done,
                        self.total,
                        self.failing,
                        self.start.elapsed().as_secs_f64()
                    );
                }
            }
            for h in handles {
                h.join().expect("a worker thread panicked")?;
            }
            Ok(written?)
        });
        self.queue_ids
            .store(queue.next_id.load(Ordering::SeqCst), Ordering::SeqCst);
        started?;
        // Every case of a pass that ran to its end has a record: one that has none was lost
        // between runner and worker, and is a failure, never a silent gap in the reports.
        if !self.halted() {
            for case in cases {
                records.entry(case.full_name()).or_insert_with(|| {
                    let why = "no worker reported it (lost between the runner and its worker)";
                    lost(case, Status::Crash, why.into(), 0.0)
                });
            }
        }
        Ok(records)
    }

    /// Counts and prints a failing record, and halts the run at `--max-fails`.
    fn failed(&mut self, r: &Record) {
        if r.status.is_failure() {
            self.failing += 1;
            eprintln!("{}", line(r));
            if self.failing >= self.options.max_fails.unwrap_or(usize::MAX) {
                self.halt.store(true, Ordering::SeqCst);
            }
        }
    }

    /// Keeps one device row per name: the first failing one over passing ones (each worker's
    /// context reports its canary and teardown).
    fn fold_device(&mut self, r: Record) {
        let index = self.device.iter().position(|d| d.name == r.name);
        if index.is_some_and(|i| self.device[i].status.is_failure() || !r.status.is_failure()) {
            return;
        }
        self.failed(&r);
        match index {
            Some(i) => self.device[i] = r,
            None => self.device.push(r),
        }
    }
}

/// A worker thread: takes batches until none is left or the run halts.
fn work(
    queue: &Queue,
    options: &RunnerOptions,
    halt: &AtomicBool,
    tx: &mpsc::Sender<Message>,
) -> RunResult<()> {
    loop {
        if halt.load(Ordering::SeqCst) || options.stop.load(Ordering::SeqCst) {
            return Ok(());
        }
        let Some(batch) = queue.batches.lock().expect("queue").pop_front() else {
            return Ok(());
        };
        let id = queue.next_id.fetch_add(1, Ordering::SeqCst);
        let (info, rest) = match run_worker(id, &batch, options, halt, tx) {
            Ok(done) => done,
            Err(e) => {
                // No device or no layer, or the worker's files: nothing more can run.
                halt.store(true, Ordering::SeqCst);
                return Err(e);
            }
        };
        let _ = tx.send(Message::Worker(info));
        if !rest.is_empty() {
            queue.batches.lock().expect("queue").push_front(rest);
        }
    }
}

/// The peak resident memory of process `pid` in MiB (`VmHWM`), where /proc has it.
fn peak_mib(pid: u32) -> Option<f64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// The last lines of a worker's log, for a crash report.
fn log_tail(path: &std::path::Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let lines: Vec<&str> = text.lines().rev().take(3).collect();
    let tail: Vec<&str> = lines.into_iter().rev().collect();
    if tail.is_empty() {
        String::new()
    } else {
        format!("; its log ends: {}", tail.join(" | "))
    }
}

/// Runs one batch in a fresh worker process. Returns how the worker went and the cases of the
/// batch it never started (after a crash or timeout), for another worker.
fn run_worker(
    id: usize,
    batch: &[PlannedCase],
    options: &RunnerOptions,
    halt: &AtomicBool,
    tx: &mpsc::Sender<Message>,
) -> RunResult<(WorkerInfo, Vec<PlannedCase>)> {
    let dir = options.out.join("workers");
    let list = dir.join(format!("batch-{id}.txt"));
    let log_path = dir.join(format!("worker-{id}.log"));
    let names: String = batch.iter().map(|c| c.full_name() + "\n").collect();
    std::fs::write(&list, names)?;
    let mut command = Command::new(&options.program);
    command
        .args(&options.args)
        .arg("--caselist")
        .arg(&list)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(std::fs::File::create(&log_path)?);
    // Its own process group: a terminal's Ctrl-C reaches the runner, which stops the workers
    // itself, instead of killing them mid-case (they would read as crashes). And it dies with
    // the runner: a runner killed outright (a CI job's hard timeout) leaves no worker behind.
    std::os::unix::process::CommandExt::process_group(&mut command, 0);
    // SAFETY: prctl is async-signal-safe and touches nothing of the parent's.
    unsafe {
        std::os::unix::process::CommandExt::pre_exec(&mut command, || {
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
            Ok(())
        });
    }
    for name in &options.env_remove {
        command.env_remove(name);
    }
    for (name, value) in &options.env_set {
        command.env(name, value);
    }
    let mut child = command.spawn()?;
    let stdout = child.stdout.take().expect("piped");
    let (ltx, lines) = mpsc::channel::<String>();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            if ltx.send(line).is_err() {
                break;
            }
        }
    });
    let mut worker = Worker {
        id,
        child,
        pending: batch.to_vec(),
        in_flight: None,
        step: None,
        last_event: Instant::now(),
        info: WorkerInfo {
            cases: 0,
            peak_mib: None,
            end: "ok".into(),
        },
        tx,
    };
    loop {
        if halt.load(Ordering::SeqCst) || options.stop.load(Ordering::SeqCst) {
            worker.kill();
            worker.info.end = "stopped".into();
            return Ok((worker.info, Vec::new()));
        }
        match lines.recv_timeout(Duration::from_millis(100)) {
            Ok(line) => worker.handle(&line),
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if worker.since().elapsed() < options.timeout {
                    continue;
                }
                // What arrived as the limit passed counts.
                while let Ok(line) = lines.try_recv() {
                    worker.handle(&line);
                }
                let since = worker.since();
                if since.elapsed() < options.timeout {
                    continue;
                }
                worker.kill();
                worker.info.end = "timeout".into();
                let reason = format!(
                    "ran past the {:.0} s timeout; its worker was killed",
                    options.timeout.as_secs_f64()
                );
                worker.charge(Status::Timeout, reason, since);
                return Ok((worker.info, worker.pending));
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                // The group's other processes, if the worker started any, go with it; before
                // the worker is reaped, while its pid still names the group.
                // SAFETY: signalling the worker's own process group.
                unsafe { libc::kill(-(worker.child.id() as i32), libc::SIGKILL) };
                let status = worker.child.wait()?;
                if status.success() && worker.pending.is_empty() && worker.in_flight.is_none() {
                    return Ok((worker.info, worker.pending));
                }
                if status.code() == Some(NO_DEVICE_EXIT) && worker.info.cases == 0 {
                    return Err(RunnerError::NoDevice(format!(
                        "a worker found no Vulkan device, no validation layer or not the \
                         expected driver{}",
                        log_tail(&log_path)
                    )));
                }
                let how = match (
                    status.code(),
                    std::os::unix::process::ExitStatusExt::signal(&status),
                ) {
                    (Some(code), _) => format!("exit code {code}"),
                    (None, Some(signal)) => format!("signal {signal}"),
                    _ => "an unknown status".to_owned(),
                };
                worker.info.end = format!("crash: {how}");
                let reason = format!("its worker died with {how}{}", log_tail(&log_path));
                let since = worker.last_event;
                worker.charge(Status::Crash, reason, since);
                return Ok((worker.info, worker.pending));
            }
        }
    }
}

/// Why a run ended before its report, sorted by what its caller does about it: no device is
/// the machine's (the CLI's exit 3, a CI job's "no GPU here"), the rest is the runner's own
/// trouble with files and processes (exit 6).
#[derive(Debug, thiserror::Error)]
pub enum RunnerError {
    /// A worker has no device, no validation layer, or not the driver `--expect-driver` names:
    /// nothing can run.
    #[error("{0}")]
    NoDevice(String),
    /// A file the run writes, or a worker process, failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A report file could not be written whole (nothing half-written is left).
    #[error(transparent)]
    Output(#[from] histencil_vk::Error),
}

/// What the runner's steps return.
pub type RunResult<T> = std::result::Result<T, RunnerError>;

/// One worker process as its thread follows it.
struct Worker<'a> {
    id: usize,
    child: std::process::Child,
    /// The batch's cases not yet begun.
    pending: Vec<PlannedCase>,
    in_flight: Option<(PlannedCase, Instant)>,
    /// The last step the worker said it began (`step ...`): what it was recording or waiting on.
    step: Option<String>,
    last_event: Instant,
    info: WorkerInfo,
    tx: &'a mpsc::Sender<Message>,
}

impl Worker<'_> {
    /// Where the timeout counts from: the case in flight's start, else the last line heard.
    fn since(&self) -> Instant {
        self.in_flight.as_ref().map_or(self.last_event, |(_, t)| *t)
    }

    fn take(&mut self, name: &str) -> Option<PlannedCase> {
        let i = self.pending.iter().position(|c| c.full_name() == name)?;
        Some(self.pending.remove(i))
    }

    /// One line of the worker's protocol. A case is never dropped: one begun and not reported
    /// before the next begins, or whose report cannot be read, is a crash of its own.
    fn handle(&mut self, line: &str) {
        self.last_event = Instant::now();
        let (verb, rest) = line.split_once(' ').unwrap_or((line, ""));
        match verb {
            "step" => self.step = Some(rest.to_owned()),
            "start" => {
                self.step = None;
                if let Some((case, t)) = self.in_flight.take() {
                    let why = "its worker began another case without reporting this one";
                    self.lose(&case, Status::Crash, why.into(), t);
                }
                self.in_flight = self.take(rest).map(|c| (c, Instant::now()));
            }
            "result" => {
                // What comes after a case's result (the next case's setup, a teardown) is not
                // that case's step.
                self.step = None;
                let parsed = serde_json::from_str(rest)
                    .ok()
                    .and_then(|v: Value| Record::from_json(&v));
                let Some(r) = parsed else {
                    if let Some((case, t)) = self.in_flight.take() {
                        let why = "its worker's report of it could not be read";
                        self.lose(&case, Status::Crash, why.into(), t);
                    }
                    return;
                };
                if r.scene != "device" {
                    self.info.cases += 1;
                    let name = r.full_name();
                    if self
                        .in_flight
                        .as_ref()
                        .is_some_and(|(c, _)| c.full_name() == name)
                    {
                        self.in_flight = None;
                    } else {
                        self.take(&name);
                    }
                }
                let _ = self.tx.send(Message::Record(r));
            }
            "peak" => self.info.peak_mib = rest.trim().parse().ok(),
            _ => {}
        }
    }

    fn lose(&self, case: &PlannedCase, status: Status, reason: String, since: Instant) {
        let seconds = since.elapsed().as_secs_f64();
        let _ = self
            .tx
            .send(Message::Record(lost(case, status, reason, seconds)));
    }

    /// A crash or timeout charged to the case in flight; else to the next case of the batch (a
    /// worker that died making its device), so that every failure ends a case and the run moves
    /// on; else, with its batch done (tearing its device down), to the worker's own device row,
    /// so that a crash or hang at teardown fails the run too.
    fn charge(&mut self, status: Status, reason: String, since: Instant) {
        let reason = match self.step.take() {
            Some(step) => format!("{reason}; it was {step}"),
            None => reason,
        };
        if let Some((case, t)) = self.in_flight.take() {
            self.lose(&case, status, reason, t);
        } else if !self.pending.is_empty() {
            let case = self.pending.remove(0);
            self.lose(&case, status, format!("before it began: {reason}"), since);
        } else {
            let _ = self.tx.send(Message::Record(Record {
                scene: "device".into(),
                name: format!("worker-{}", self.id),
                status,
                seconds: since.elapsed().as_secs_f64(),
                failure_type: Some(status.name().to_lowercase()),
                details: format!("after its last case: {reason}\n"),
                reason: Some(format!("after its last case: {reason}")),
                data: Value::Null,
            }));
        }
    }

    /// Kills the worker's whole process group and reaps it, its peak memory read first.
    fn kill(&mut self) {
        self.info.peak_mib = peak_mib(self.child.id()).or(self.info.peak_mib);
        // SAFETY: signalling the worker's own process group (it leads it).
        unsafe { libc::kill(-(self.child.id() as i32), libc::SIGKILL) };
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(scene: &str, case: &str, group: &str, pixels: u64) -> PlannedCase {
        PlannedCase {
            scene: scene.into(),
            case: case.into(),
            group: group.into(),
            pixels,
        }
    }

    fn record(name: &str, status: Status) -> Record {
        Record {
            scene: "s".into(),
            name: name.into(),
            status,
            seconds: 0.0,
            reason: Some("why".into()),
            failure_type: None,
            details: String::new(),
            data: Value::Null,
        }
    }

    #[test]
    fn batches_keep_groups_apart_split_them_and_put_the_dearest_first() {
        let cases = [
            case("a", "1", "a-1x1", 1),
            case("a", "2", "a-1x1", 1),
            case("a", "3", "a-1x1", 1),
            case("a", "4", "a-big", 1_000_000),
        ];
        let b = batches(&cases, 2);
        let names: Vec<Vec<&str>> = b
            .iter()
            .map(|b| b.iter().map(|c| c.case.as_str()).collect())
            .collect();
        assert_eq!(names, [vec!["4"], vec!["1", "2"], vec!["3"]]);
    }

    #[test]
    fn the_baseline_and_flake_patterns_classify_records() {
        let baseline =
            Baseline::parse("s/known,Fail\ns/fixed,Fail\ns/crashes,Crash\n", "b").unwrap();
        let flakes = Patterns::parse("wobbly", "f").unwrap();
        let c = |name, status| classify(record(name, status), &baseline, &flakes).status;
        assert_eq!(c("known", Status::Fail), Status::ExpectedFail);
        assert_eq!(c("fixed", Status::Pass), Status::UnexpectedPass);
        assert_eq!(c("crashes", Status::Fail), Status::Fail, "another failure");
        assert_eq!(c("crashes", Status::Crash), Status::ExpectedFail);
        assert_eq!(c("new", Status::Fail), Status::Fail);
        assert_eq!(c("wobbly", Status::Timeout), Status::Flake);
        assert_eq!(
            c("wobbly", Status::ValidationLayerMuted),
            Status::ValidationLayerMuted
        );
        assert_eq!(c("other", Status::Pass), Status::Pass);
    }
}
