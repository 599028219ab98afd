//! Transport benchmark: for in-process, iceoryx2 and zenoh, the median round
//! trip of one task at a time through the bare transport and through the
//! farm, the farm's tasks/s with two worker processes, for a no-op result and
//! a 1 MiB history; then the two-worker speed-up of a study's sweep.
//! Run by `scripts/bench/transports`.
//!
//! Usage: transport_bench CEILFARM_BIN [TASKS] [REPEATS] [SPEEDUP_STUDY.toml]
//! (TASKS = 0: the speed-up alone).
//!
//! `transport_bench CEILFARM_BIN --security [TASKS] [REPEATS]`: the cost of
//! zenoh's security instead: plain zenoh (`tcp/`) against zenoh with the
//! configurations `ceilfarm farm certs` writes (`tls/`, mutual TLS, access
//! control) on loopback, the same tasks, run in pairs (plain, then
//! secured), each pair's ratio printed, then their median, quartiles and
//! range. The per-sweep MAC is on in both; its own cost (sealing and
//! opening a task and its result, less encoding and decoding them) is
//! measured beside, with the CPU per task of iceoryx2, whose only security
//! is the MAC.
//!
//! `transport_bench CEILFARM_BIN --one TRANSPORT RESULT TASKS`: one farm run
//! and nothing else (for a profiler, or to time builds against each other
//! as whole processes): TRANSPORT `iceoryx2`, `zenoh` or `zenoh-tls`,
//! RESULT `small` or `1MiB`, 2 workers; prints wall and CPU per task.

use coordinator::farm::{run_farm, FarmSettings, ResultSink};
use coordinator::study::{Study, TransportKind};
use coordinator::transports::{coordinator_transport_secured, ZenohSecurity};
use protocol::{ModelSpec, Task, TaskId, TaskResult, Transport, TransportEvent};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

struct Null;
impl ResultSink for Null {
    fn accept(&mut self, _: &[TaskResult]) -> Result<(), String> {
        Ok(())
    }
}

#[path = "common/cpu.rs"]
mod cpu;

/// CPU seconds of this process and of its waited-for children (the workers).
fn cpu_s() -> f64 {
    let (own, children) = cpu::cpu_s();
    own + children
}

/// Where one run's coordinator listens and its workers connect.
struct Setup {
    kind: TransportKind,
    endpoint: Option<String>,
    /// A folder `ceilfarm farm certs` wrote (zenoh over TLS), or none.
    certs: Option<std::path::PathBuf>,
}

impl Setup {
    /// zenoh on loopback over TLS with the configurations in `certs`.
    fn secured(certs: &std::path::Path) -> Self {
        let l = std::net::TcpListener::bind("127.0.0.1:0").expect("port");
        let endpoint = format!("tls/127.0.0.1:{}", l.local_addr().expect("addr").port());
        Self { kind: TransportKind::Zenoh, endpoint: Some(endpoint), certs: Some(certs.into()) }
    }

    fn new(kind: TransportKind, run: usize) -> Self {
        let endpoint = match kind {
            TransportKind::InProcess => None,
            TransportKind::Iceoryx2 => Some(format!("cfbench{}r{run}", std::process::id())),
            TransportKind::Zenoh => {
                let l = std::net::TcpListener::bind("127.0.0.1:0").expect("port");
                Some(format!("tcp/127.0.0.1:{}", l.local_addr().expect("addr").port()))
            }
        };
        Self { kind, endpoint, certs: None }
    }

    fn transport(&self, workers: usize) -> Box<dyn Transport> {
        let security = ZenohSecurity {
            config: self.certs.as_ref().map(|d| d.join("coordinator.json5")),
            insecure: false,
        };
        coordinator_transport_secured(self.kind, workers, self.endpoint.as_deref(), &security)
            .expect("transport")
    }

    /// Starts `n` worker processes (none for in-process).
    fn workers(&self, bin: &str, n: usize) -> Vec<Child> {
        if self.kind == TransportKind::InProcess {
            return Vec::new();
        }
        (0..n)
            .map(|i| {
                let mut cmd = Command::new(bin);
                cmd.args(["worker", "--transport", self.kind.as_str()])
                    .args(["--connect", self.endpoint.as_deref().expect("endpoint")]);
                // A certificate names its worker; otherwise name it here.
                match &self.certs {
                    Some(dir) => {
                        cmd.arg("--zenoh-config").arg(dir.join(format!("worker-{}.json5", i + 1)))
                    }
                    None => cmd.args(["--name", &format!("bench{i}")]),
                };
                cmd.stdout(Stdio::null()).stderr(Stdio::null()).spawn().expect("spawn worker")
            })
            .collect()
    }
}

fn stop(children: Vec<Child>) {
    for c in &children {
        let _ = Command::new("kill").args(["-TERM", &c.id().to_string()]).status();
    }
    for mut c in children {
        let _ = c.wait();
    }
}

fn noop(history_samples: usize) -> ModelSpec {
    ModelSpec {
        kind: "noop".into(),
        options_json: format!("{{\"history_samples\": {history_samples}}}"),
        param_names: vec!["a".into()],
        outputs: vec![],
    }
}

fn tasks(n: usize) -> Vec<Task> {
    (0..n).map(|i| Task { id: TaskId(i as u64), params: vec![i as f64] }).collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median round trip (s) of `n` tasks sent one at a time on the bare transport.
fn bare_round_trip(setup: &Setup, bin: &str, spec: &ModelSpec, n: usize) -> f64 {
    let mut t = setup.transport(1);
    let children = setup.workers(bin, 1);
    t.start(&format!("{:032x}", rand_hash()), spec).expect("start");
    let joined_by = Instant::now() + Duration::from_secs(60);
    let worker = loop {
        assert!(Instant::now() < joined_by, "no worker joined within 60 s");
        if let Some(TransportEvent::Joined { worker, .. }) =
            t.next_event(Duration::from_secs(5)).expect("event")
        {
            break worker;
        }
    };
    let mut times = Vec::with_capacity(n);
    for task in tasks(n) {
        let t0 = Instant::now();
        t.send(worker, task).expect("send");
        loop {
            match t.next_event(Duration::from_secs(30)).expect("event") {
                Some(TransportEvent::Result { .. }) => break,
                Some(_) => {}
                None => panic!("no result within 30 s"),
            }
        }
        times.push(t0.elapsed().as_secs_f64());
    }
    t.shutdown();
    stop(children);
    median(times)
}

fn rand_hash() -> u128 {
    let t = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).expect("clock");
    t.as_nanos() ^ ((std::process::id() as u128) << 64)
}

/// Counts tasks finished once all expected workers are in.
struct Clock {
    expected: usize,
    joined: usize,
    full: Option<Instant>,
    after: usize,
}

impl coordinator::farm::FarmObserver for Clock {
    fn finished(&mut self, _: &TaskResult) {
        if self.full.is_some() {
            self.after += 1;
        }
    }
    fn membership(&mut self, joined: bool, _: protocol::WorkerId, _: &str) {
        if joined {
            self.joined += 1;
            if self.joined == self.expected && self.full.is_none() {
                self.full = Some(Instant::now());
            }
        }
    }
}

/// Seconds per task once every worker is in (joining is not the farm's
/// overhead), and CPU seconds per task of the whole run, coordinator and workers.
fn farm_run(
    setup: &Setup,
    bin: &str,
    spec: &ModelSpec,
    tasks: Vec<Task>,
    workers: usize,
    window: usize,
) -> (f64, f64) {
    let mut t = setup.transport(workers);
    let children = setup.workers(bin, workers);
    let settings = FarmSettings { window_per_slot: window, ..FarmSettings::default() };
    let hash = format!("{:032x}", rand_hash());
    let n = tasks.len();
    let mut clock = Clock { expected: workers, joined: 0, full: None, after: 0 };
    let (c0, start) = (cpu_s(), Instant::now());
    let s =
        run_farm(t.as_mut(), &hash, spec, tasks, &settings, &mut Null, &mut clock).expect("farm");
    let end = Instant::now();
    stop(children);
    let cpu = cpu_s() - c0;
    if std::env::var_os("BENCH_CPU_SPLIT").is_some() {
        let (own, kids) = cpu::cpu_s();
        eprintln!(
            "{} x{workers}: own total {own:.2} s, children total {kids:.2} s",
            setup.kind.as_str()
        );
    }
    // A re-issue without a loss is a dropped link too (how the TLS link's
    // race showed in small tasks): the security comparison reports it.
    let report = REPORT_SHORT_RUNS.load(std::sync::atomic::Ordering::Relaxed);
    if s.ok != n || (report && s.reissued > 0) {
        let secured = if setup.certs.is_some() { " (secured)" } else { "" };
        let what =
            format!("not every task once: {}{secured} x{workers}: {s:?}", setup.kind.as_str());
        // The security comparison reports such a run and goes on.
        assert!(report, "{what}");
        println!("  ! {what}");
    }
    // A run so short that it ended before every worker was in: time it all.
    let full = clock.full.unwrap_or(start);
    let done = if clock.full.is_some() { clock.after } else { n };
    ((end - full).as_secs_f64() / done.max(1) as f64, cpu / n as f64)
}

/// Whether a run that did not finish every task is reported instead of fatal.
static REPORT_SHORT_RUNS: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

const KINDS: [TransportKind; 3] =
    [TransportKind::InProcess, TransportKind::Iceoryx2, TransportKind::Zenoh];

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(2).map(String::as_str) == Some("--security") {
        let n: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(2000);
        let repeats: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(5);
        security_cost(&args[1], n, repeats);
        return;
    }
    if args.get(2).map(String::as_str) == Some("--one") {
        one_run(&args[1], &args[3..]);
        return;
    }
    let bin = args.get(1).expect("usage: transport_bench CEILFARM_BIN [TASKS] [REPEATS] [STUDY]");
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2000);
    let repeats: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(3);
    println!(
        "{:<11} {:<6} {:>12} {:>12} {:>8} {:>12} {:>14}",
        "transport", "result", "bare rtt us", "farm rtt us", "ratio", "farm tasks/s", "cpu us/task"
    );
    let mut run = 0;
    // TASKS = 0 runs the speed-up alone.
    for kind in KINDS.into_iter().filter(|_| n > 0) {
        for (label, samples, count) in [("small", 0usize, n), ("1MiB", 131_072, n.min(200))] {
            let spec = noop(samples);
            let (mut bare, mut seq, mut thr, mut cpu) = (vec![], vec![], vec![], vec![]);
            for _ in 0..repeats {
                run += 1;
                bare.push(bare_round_trip(&Setup::new(kind, run), bin, &spec, count.min(500)));
                run += 1;
                let m = count.min(500);
                let (per_task, _) = farm_run(&Setup::new(kind, run), bin, &spec, tasks(m), 1, 1);
                seq.push(per_task);
                run += 1;
                let (per_task, c) =
                    farm_run(&Setup::new(kind, run), bin, &spec, tasks(count), 2, 2);
                thr.push(1.0 / per_task);
                cpu.push(c);
            }
            let (b, s) = (median(bare), median(seq));
            println!(
                "{:<11} {label:<6} {:>12.1} {:>12.1} {:>8.2} {:>12.0} {:>14.1}",
                kind.as_str(),
                b * 1e6,
                s * 1e6,
                s / b,
                median(thr),
                median(cpu) * 1e6
            );
        }
    }
    if let Some(path) = args.get(4) {
        speedup(bin, path, repeats, &mut run);
    }
}

/// One farm run with 2 workers: `[TRANSPORT, RESULT, TASKS]` as the usage
/// says; prints wall and CPU (coordinator + workers) per task.
fn one_run(bin: &str, args: &[String]) {
    let usage =
        "usage: transport_bench CEILFARM_BIN --one iceoryx2|zenoh|zenoh-tls small|1MiB TASKS";
    let [transport, result, n] = args else { panic!("{usage}") };
    let n: usize = n.parse().expect(usage);
    let samples = match result.as_str() {
        "small" => 0,
        "1MiB" => 131_072,
        _ => panic!("{usage}"),
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let setup = match transport.as_str() {
        "iceoryx2" => Setup::new(TransportKind::Iceoryx2, 0),
        "zenoh" => Setup::new(TransportKind::Zenoh, 0),
        "zenoh-tls" => {
            write_loopback_lab(dir.path());
            Setup::secured(dir.path())
        }
        _ => panic!("{usage}"),
    };
    let (wall, cpu) = farm_run(&setup, bin, &noop(samples), tasks(n), 2, 2);
    println!(
        "{transport} {result} x2: wall {:.1} us, cpu {:.1} us per task",
        wall * 1e6,
        cpu * 1e6
    );
}

/// Two-worker speed-up of a study's sweep over each transport.
fn speedup(bin: &str, path: &str, repeats: usize, run: &mut usize) {
    let study = Study::load(std::path::Path::new(path)).expect("study");
    if worker::registry::kinds().iter().all(|k| *k != study.model_kind) {
        println!("speed-up: skipped, model kind {} is not in this build", study.model_kind);
        return;
    }
    let unit = coordinator::design::draw(
        study.design.method,
        study.design.n,
        study.parameters.len(),
        study.design.seed,
    );
    let points = unit.to_physical(&study.parameters);
    let tasks: Vec<Task> = points
        .into_iter()
        .enumerate()
        .map(|(i, params)| Task { id: TaskId(i as u64), params })
        .collect();
    let spec = study.model_spec();
    println!("\nspeed-up on {} ({} runs of {}):", path, tasks.len(), study.model_kind);
    println!(
        "(cpu = coordinator + workers, ms per task; load = 1-min load average before the runs)"
    );
    direct_speedup(&spec, &tasks, repeats);
    for kind in KINDS {
        let (mut walls, mut cpus) = ([vec![], vec![]], [vec![], vec![]]);
        let load = load_average();
        for _ in 0..repeats {
            for (slot, workers) in [(0, 1usize), (1, 2)] {
                *run += 1;
                let setup = Setup::new(kind, *run);
                let (per_task, cpu) = farm_run(&setup, bin, &spec, tasks.clone(), workers, 2);
                walls[slot].push(per_task * tasks.len() as f64);
                cpus[slot].push(cpu);
            }
        }
        let (one, two) = (median(walls[0].clone()), median(walls[1].clone()));
        let (c1, c2) = (median(cpus[0].clone()), median(cpus[1].clone()));
        let ratios: Vec<String> =
            walls[0].iter().zip(&walls[1]).map(|(a, b)| format!("{:.2}", a / b)).collect();
        println!(
            "{:<11} 1 worker {:>8.3} s   2 workers {:>8.3} s   speed-up {:.2} (each {})   \
             cpu {:.1} / {:.1}   load {load:.2}",
            kind.as_str(),
            one,
            two,
            one / two,
            ratios.join(" "),
            c1 * 1e3,
            c2 * 1e3,
        );
    }
}

/// The machine's own ceiling: the same tasks on 1 and 2 plain threads, each
/// thread with its own model and no farm, no transport, no store.
fn direct_speedup(spec: &ModelSpec, tasks: &[Task], repeats: usize) {
    let load = load_average();
    let (mut one, mut two) = (vec![], vec![]);
    for _ in 0..repeats {
        one.push(direct_run(spec, tasks, 1));
        two.push(direct_run(spec, tasks, 2));
    }
    let ratios: Vec<String> = one.iter().zip(&two).map(|(a, b)| format!("{:.2}", a / b)).collect();
    let (a, b) = (median(one), median(two));
    println!(
        "{:<11} 1 thread {:>8.3} s   2 threads {:>7.3} s   speed-up {:.2} (each {})   load {load:.2}",
        "no farm",
        a,
        b,
        a / b,
        ratios.join(" ")
    );
}

/// Wall seconds to run `tasks` split round-robin over `threads` plain threads.
fn direct_run(spec: &ModelSpec, tasks: &[Task], threads: usize) -> f64 {
    let start = Instant::now();
    std::thread::scope(|scope| {
        for t in 0..threads {
            scope.spawn(move || {
                let model = worker::registry::build(spec).expect("model");
                for task in tasks.iter().skip(t).step_by(threads) {
                    let out =
                        worker::run::run_task(&*model, &spec.param_names, task.id, &task.params);
                    assert!(matches!(out, protocol::Outcome::Ok(_)), "task {:?} failed", task.id);
                }
            });
        }
    });
    start.elapsed().as_secs_f64()
}

/// The 1-minute load average (0 if unknown).
fn load_average() -> f64 {
    let text = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    text.split_whitespace().next().and_then(|v| v.parse().ok()).unwrap_or(0.0)
}

/// Seconds this thread has run on a CPU (Linux `/proc/thread-self/schedstat`, ns).
fn thread_cpu_s() -> f64 {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    let ns = text.split_whitespace().next().and_then(|v| v.parse::<f64>().ok());
    ns.unwrap_or(0.0) * 1e-9
}

/// The p-quantile of `v` (nearest rank).
fn quantile(mut v: Vec<f64>, p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

/// `median (q1–q3, min–max)` of `v`, each as `x{:.2}`.
fn spread(v: &[f64]) -> String {
    let q = |p| quantile(v.to_vec(), p);
    format!(
        "x{:.2} (q1-q3 x{:.2}-{:.2}, range x{:.2}-{:.2})",
        q(0.5),
        q(0.25),
        q(0.75),
        q(0.0),
        q(1.0)
    )
}

/// CPU seconds per task, on this thread, of what the MAC adds to a task's
/// trip: sealing and opening the task and its result (as the coordinator
/// and a worker do), less encoding and decoding the same messages without
/// a MAC (which every transport did before). Median of 5 rounds of at
/// least 0.3 s each over `n` tasks (held in memory: keep `n` small).
fn mac_cost(spec: &ModelSpec, n: usize) -> f64 {
    use protocol::seal::{Direction, SweepKey, SweepMac};
    use protocol::{codec, FromWorker, ToWorker};
    let mac = SweepMac::new(SweepKey::random(), &format!("{:032x}", rand_hash()));
    let model = worker::registry::build(spec).expect("model");
    let messages: Vec<(ToWorker, FromWorker)> = tasks(n)
        .into_iter()
        .map(|task| {
            let outcome = worker::run::run_task(&*model, &spec.param_names, task.id, &task.params);
            let result = TaskResult { id: task.id, outcome, wall_s: 0.0, host: "bench".into() };
            (ToWorker::Task(task), FromWorker::Result(result))
        })
        .collect();
    // The scheduler's count moves in ticks: run for at least 0.3 s.
    let time = |sealed: bool| {
        let (c0, mut done) = (thread_cpu_s(), 0);
        while done == 0 || thread_cpu_s() - c0 < 0.3 {
            for (seq, (task, result)) in messages.iter().enumerate() {
                let seq = seq as u64;
                if sealed {
                    let t = mac.seal(Direction::ToWorker, seq, task).expect("seal");
                    let _: (u64, ToWorker) = mac.open(Direction::ToWorker, &t).expect("open");
                    let r = mac.seal(Direction::FromWorker, seq, result).expect("seal");
                    let _: (u64, FromWorker) = mac.open(Direction::FromWorker, &r).expect("open");
                } else {
                    let t = codec::encode(task).expect("encode");
                    let _: ToWorker = codec::decode(&t).expect("decode");
                    let r = codec::encode(result).expect("encode");
                    let _: FromWorker = codec::decode(&r).expect("decode");
                }
            }
            done += n;
        }
        (thread_cpu_s() - c0) / done as f64
    };
    let rounds: Vec<f64> = (0..5).map(|_| time(true) - time(false)).collect();
    median(rounds)
}

/// A lab's CA, coordinator and two worker certificates for loopback in `dir`.
fn write_loopback_lab(dir: &std::path::Path) {
    let lab = coordinator::farm_certs::LabSettings {
        workers: 2,
        hosts: vec!["127.0.0.1".into(), "localhost".into()],
        port: 7447,
        validity_days: 1,
    };
    coordinator::farm_certs::write_lab(dir, &lab).expect("farm certs");
}

/// Plain zenoh against zenoh with `farm certs`' TLS, mutual authentication
/// and access control, on loopback: per pair (plain run, then secured run,
/// the same tasks) the one-at-a-time round trip through the farm (1
/// worker), and wall and CPU (coordinator + workers) per task with 2
/// workers; each pair's ratio secured / plain, then their median, quartiles
/// and range, and each column's own medians. The MAC is on in both; what
/// it costs on its own is measured per pair beside the CPU per task of
/// iceoryx2 with 2 workers (whose only security is the MAC) and of plain
/// zenoh.
fn security_cost(bin: &str, n: usize, repeats: usize) {
    REPORT_SHORT_RUNS.store(true, std::sync::atomic::Ordering::Relaxed);
    let dir = tempfile::tempdir().expect("temp dir");
    write_loopback_lab(dir.path());
    println!("zenoh on loopback, plain (tcp/) vs secured (tls/, mTLS, access control);");
    println!("rtt: one task at a time, 1 worker; wall, cpu: per task, 2 workers");
    println!("(cpu = coordinator + workers; ratio = secured / plain; load = 1-min average)");
    println!("mac: CPU of sealing + opening a task and its result, less encode + decode;");
    println!(
        "iox cpu: iceoryx2 (MAC only), cpu per task, 2 workers; mac share = mac / (cpu - mac)"
    );
    let mut run = 0;
    for (label, samples, count) in [("small", 0usize, n), ("1MiB", 131_072, n.min(200))] {
        let spec = noop(samples);
        let m = count.min(300);
        let mut ratios: [Vec<f64>; 3] = [vec![], vec![], vec![]];
        let mut own: [[Vec<f64>; 2]; 3] = Default::default();
        let (mut macs, mut iox) = (vec![], vec![]);
        println!("\n{label}: {count} tasks (rtt: {m})");
        println!(
            "{:<6} {:>24} {:>24} {:>24} {:>8} {:>8} {:>5}",
            "pair",
            "rtt us plain secured",
            "wall us plain secured",
            "cpu us plain secured",
            "mac us",
            "iox cpu",
            "load"
        );
        for pair in 1..=repeats {
            let load = load_average();
            let mut row = [[0.0; 2]; 3];
            for (i, secured) in [false, true].into_iter().enumerate() {
                let setup = || match secured {
                    true => Setup::secured(dir.path()),
                    false => Setup::new(TransportKind::Zenoh, 0),
                };
                let (rtt, _) = farm_run(&setup(), bin, &spec, tasks(m), 1, 1);
                let (wall, cpu) = farm_run(&setup(), bin, &spec, tasks(count), 2, 2);
                row[0][i] = rtt * 1e6;
                row[1][i] = wall * 1e6;
                row[2][i] = cpu * 1e6;
            }
            run += 1;
            let iox_setup = Setup::new(TransportKind::Iceoryx2, run);
            let (_, iox_cpu) = farm_run(&iox_setup, bin, &spec, tasks(count), 2, 2);
            iox.push(iox_cpu * 1e6);
            macs.push(mac_cost(&spec, m.min(20)) * 1e6);
            let cells: Vec<String> = row
                .iter()
                .zip(ratios.iter_mut())
                .zip(own.iter_mut())
                .map(|(([plain, secured], r), o)| {
                    r.push(secured / plain);
                    o[0].push(*plain);
                    o[1].push(*secured);
                    format!("{plain:>8.1} {secured:>8.1} x{:.2}", secured / plain)
                })
                .collect();
            println!(
                "{:<6} {:>24} {:>24} {:>24} {:>8.1} {:>8.1} {:>5.1}",
                pair,
                cells[0],
                cells[1],
                cells[2],
                macs[pair - 1],
                iox[pair - 1],
                load
            );
        }
        let names = ["rtt", "wall", "cpu"];
        for ((name, r), o) in names.iter().zip(&ratios).zip(&own) {
            let (plain, secured) = (median(o[0].clone()), median(o[1].clone()));
            println!(
                "{name:<5} secured/plain {}; medians {plain:.1} -> {secured:.1} us",
                spread(r)
            );
        }
        let (mac, iox_cpu) = (median(macs), median(iox));
        let zenoh_cpu = median(own[2][0].clone());
        println!(
            "mac   {mac:.1} us per task: iceoryx2 cpu {iox_cpu:.1} us, mac share {:.1} %; \
             plain zenoh cpu {zenoh_cpu:.1} us, mac share {:.1} %",
            100.0 * mac / (iox_cpu - mac),
            100.0 * mac / (zenoh_cpu - mac)
        );
    }
}
