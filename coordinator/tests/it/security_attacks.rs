//! Issue 56's attacks against a secured zenoh sweep (TLS with mutual
//! authentication, access control, per-sweep MAC), each by an attacker
//! written with the zenoh crate:
//!
//! - no credentials (plain TCP), no client certificate, a certificate of
//!   another CA, a listed worker's certificate of the lab's CA that has
//!   expired: the connection is refused;
//! - a certificate of the lab's CA whose common name the access control
//!   does not list: connected, but it receives no Welcome, no task query
//!   and nothing its fake Welcome, liveliness tokens, oversized Hellos or
//!   puts could change;
//! - a copy of the real worker's own certificate that never said Hello (so
//!   has no sweep key): it serves the real worker's task key, hears its
//!   task queries and answers each with a forged result, an unsealed
//!   result, a result sealed under a guessed key, an error reply and a
//!   hand-back; none counts (the MAC);
//! - another listed worker's certificate that said Hello (so holds the
//!   sweep's key) and serves the real worker's task key (and every task
//!   key), answering what it hears with correctly sealed forgeries: the
//!   access control grants a certificate only the task key of its own
//!   common name, so it hears no task query and none of its answers counts;
//! - a listed worker certificate that said Hello and plays the
//!   coordinator: it serves a fake Welcome on the Welcome keys and sends
//!   sealed fake tasks to the real worker's task key; the access control's
//!   roles drop both at the coordinator, so another listed worker's Hello
//!   hears only the real Welcome and no fake task is answered;
//! - the real worker's configuration with another `--name`: refused before
//!   it connects, naming the certificate's name.
//!
//! The sweep completes with no failed or re-issued task and its export is
//! byte-identical to an unattacked in-process run.

use coordinator::farm_certs::{Identity, LabCa, Validity, COORDINATOR_NAME};
use coordinator::farm_zenoh_config::{coordinator_config, worker_config};
use protocol::seal::{Direction, SweepKey, SweepMac, KEY_BYTES};
use protocol::{codec, FromWorker, Outcome, Outputs, TaskId, TaskResult};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use zenoh::Wait;

fn bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_ceilfarm"))
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// The borehole study, 40 points at 40 ms each: a sweep of about a second
/// on two worker threads, long enough for the attackers to act during it.
fn study(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("configs/borehole.toml")).unwrap();
    let text = text.replace("n = 200", "n = 40").replace("cost_ms = 0 ", "cost_ms = 40");
    let path = dir.join("borehole.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A zenoh client session of `text`'s configuration at `endpoint`, giving
/// up after 3 s.
fn client(text: &str, endpoint: &str) -> zenoh::Result<zenoh::Session> {
    let mut cfg = zenoh::Config::from_json5(text)?;
    cfg.insert_json5("mode", "\"client\"")?;
    cfg.insert_json5("connect/endpoints", &format!("[\"{endpoint}\"]"))?;
    cfg.insert_json5("connect/timeout_ms", "3000")?;
    cfg.insert_json5("scouting/multicast/enabled", "false")?;
    zenoh::open(cfg).wait()
}

fn run_ok(args: &[&str]) -> String {
    let out = Command::new(bin()).args(args).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "ceilfarm {args:?}: {err}");
    String::from_utf8(out.stdout).unwrap()
}

fn export(store: &Path, dir: &Path, name: &str) -> Vec<u8> {
    let csv = dir.join(name);
    run_ok(&["export", store.to_str().unwrap(), "--out", csv.to_str().unwrap()]);
    std::fs::read(csv).unwrap()
}

struct Kill(Child);
impl Drop for Kill {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// What the unlisted-but-connected attacker saw and did.
#[derive(Default)]
struct Seen {
    welcomes: AtomicUsize,
    /// Queries it heard from others (task queries, workers' Hellos).
    task_queries: AtomicUsize,
    hellos_sent: AtomicUsize,
}

/// A lab-CA certificate the access control does not list: tries every
/// path in until `stop`.
fn unlisted_attacker(
    session: zenoh::Session,
    prefix: String,
    seen: Arc<Seen>,
    stop: Arc<AtomicBool>,
) {
    let s = &session;
    // Listens on every key of the farm: task queries and workers' Hellos,
    // answered with hand-backs and a fake Welcome naming /dev/zero.
    let remote = zenoh::sample::Locality::Remote;
    let tasks = s.declare_queryable("ceilfarm/**").allowed_origin(remote).wait().unwrap();
    let fake = protocol::ToWorker::Welcome {
        study_hash: "0".repeat(64),
        model: protocol::ModelSpec {
            kind: "ceiling".into(),
            options_json: r#"{"spec": "/dev/zero"}"#.into(),
            param_names: vec![],
            outputs: vec![],
        },
        key: SweepKey::from_bytes([0; KEY_BYTES]),
    };
    let fake = codec::encode(&fake).unwrap();
    let mut tokens = Vec::new();
    let mut k = 0;
    while !stop.load(Ordering::Relaxed) {
        k += 1;
        // Fake liveliness tokens of names that never said Hello, and of one that tries.
        if k <= 50 {
            tokens.push(s.liveliness().declare_token(format!("{prefix}/alive/fake{k}/64")).wait());
            tokens.push(
                s.liveliness().declare_token(format!("{prefix}/alive/intruder{k}/64")).wait(),
            );
        }
        let hello = FromWorker::Hello {
            proto: protocol::PROTOCOL_VERSION,
            name: format!("intruder{k}"),
            threads: 64,
            study: None,
        };
        for payload in [codec::encode(&hello).unwrap(), oversized_hello()] {
            let replies = s
                .get("ceilfarm/*/welcome")
                .allowed_destination(remote)
                .payload(payload)
                .timeout(Duration::from_millis(300))
                .wait()
                .unwrap();
            seen.hellos_sent.fetch_add(1, Ordering::Relaxed);
            while let Ok(r) = replies.recv() {
                if r.result().is_ok() {
                    seen.welcomes.fetch_add(1, Ordering::Relaxed);
                }
            }
        }
        let _ = s.put("ceilfarm/x/task/w", vec![0u8; 64]).wait();
        while let Ok(Some(q)) = tasks.try_recv() {
            seen.task_queries.fetch_add(1, Ordering::Relaxed);
            let _ = q.reply(q.key_expr().clone(), fake.clone()).wait();
            let _ = q.reply_err("hand-back: flood").wait();
        }
    }
}

/// A Hello whose name claims 1 GiB in 13 bytes (issue 56).
fn oversized_hello() -> Vec<u8> {
    let mut bytes = protocol::PROTOCOL_VERSION.to_le_bytes().to_vec();
    bytes.extend_from_slice(&[0, 2, 0xFC]);
    bytes.extend_from_slice(&(1u32 << 30).to_le_bytes());
    bytes.extend_from_slice(b"evil");
    bytes
}

/// A copy of the real worker's certificate without a Hello (no sweep key):
/// serves the real worker's task key and answers every task query it hears
/// with forgeries. Returns how many it answered.
fn keyless_insider(session: zenoh::Session, task_key: String, stop: Arc<AtomicBool>) -> usize {
    let tasks = session.declare_queryable(task_key).complete(false).wait().unwrap();
    let guess = SweepMac::new(SweepKey::from_bytes([7; KEY_BYTES]), "guess");
    let mut answered = 0;
    while !stop.load(Ordering::Relaxed) {
        let Ok(Some(q)) = tasks.recv_timeout(Duration::from_millis(50)) else { continue };
        answered += 1;
        for id in 0..64 {
            let outputs = Outputs { scalars: vec![("y".into(), 12345.0)], histories: vec![] };
            let forged = FromWorker::Result(TaskResult {
                id: TaskId(id),
                outcome: Outcome::Ok(outputs),
                wall_s: 0.0,
                host: "evil".into(),
            });
            let _ = q.reply(q.key_expr().clone(), codec::encode(&forged).unwrap()).wait();
            let sealed = guess.seal(Direction::FromWorker, id, &forged).unwrap();
            let _ = q.reply(q.key_expr().clone(), sealed).wait();
        }
        let back = FromWorker::HandBack { id: TaskId(0), reason: "flood".into() };
        let _ = q.reply(q.key_expr().clone(), codec::encode(&back).unwrap()).wait();
        let _ = q.reply_err("hand-back: flood").wait();
        let _ = q.reply_err("model refused").wait();
    }
    answered
}

/// What another listed worker's certificate, holding the sweep's key, got
/// from serving the real worker's task key.
#[derive(Default)]
struct Impostor {
    /// Its Hello got the real Welcome (so it held the key).
    joined: AtomicBool,
    /// Task queries it heard, and the sealed forgeries it answered them with.
    heard: AtomicUsize,
    forged: AtomicUsize,
}

/// Another listed worker's certificate that says Hello (so holds the
/// sweep's key), then serves the real worker's task key `victim` (and, for
/// good measure, every task key) and answers each task query it hears with
/// a result sealed for its lease: y = 12345, at once, so it would win the
/// race against the real worker.
fn key_holding_impostor(
    session: zenoh::Session,
    name: &str,
    victim: String,
    seen: Arc<Impostor>,
    stop: Arc<AtomicBool>,
) {
    let Some(mac) = join_for_key(&session, name, &stop) else { return };
    seen.joined.store(true, Ordering::Relaxed);
    let remote = zenoh::sample::Locality::Remote;
    let mut queryables = Vec::new();
    for key in [victim, "ceilfarm/*/task/*".to_string()] {
        let (mac, seen) = (mac.clone(), seen.clone());
        let q = session
            .declare_queryable(key)
            .allowed_origin(remote)
            .callback(move |q| {
                seen.heard.fetch_add(1, Ordering::Relaxed);
                let bytes = q.payload().map(|p| p.to_bytes().into_owned()).unwrap_or_default();
                let Ok((seq, protocol::ToWorker::Task(task))) =
                    mac.open::<protocol::ToWorker>(Direction::ToWorker, &bytes)
                else {
                    return;
                };
                let outputs = Outputs { scalars: vec![("y".into(), 12345.0)], histories: vec![] };
                let forged = FromWorker::Result(TaskResult {
                    id: task.id,
                    outcome: Outcome::Ok(outputs),
                    wall_s: 0.0,
                    host: "impostor".into(),
                });
                let sealed = mac.seal(Direction::FromWorker, seq, &forged).unwrap();
                if q.reply(q.key_expr().clone(), sealed).wait().is_ok() {
                    seen.forged.fetch_add(1, Ordering::Relaxed);
                }
            })
            .wait()
            .unwrap();
        queryables.push(q);
    }
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Says Hello as `name` until the coordinator's Welcome arrives (or
/// `stop`): the sweep's sealer.
fn join_for_key(s: &zenoh::Session, name: &str, stop: &AtomicBool) -> Option<SweepMac> {
    let hello = FromWorker::Hello {
        proto: protocol::PROTOCOL_VERSION,
        name: name.into(),
        threads: 1,
        study: None,
    };
    while !stop.load(Ordering::Relaxed) {
        let replies = s
            .get("ceilfarm/*/welcome")
            .allowed_destination(zenoh::sample::Locality::Remote)
            .payload(codec::encode(&hello).unwrap())
            .timeout(Duration::from_millis(500))
            .wait()
            .unwrap();
        while let Ok(r) = replies.recv() {
            let Ok(sample) = r.result() else { continue };
            if let Ok(protocol::ToWorker::Welcome { study_hash, key, .. }) =
                codec::decode(&sample.payload().to_bytes())
            {
                return Some(SweepMac::new(key, &study_hash));
            }
        }
    }
    None
}

/// What the joined insider and the probe saw.
#[derive(Default)]
struct Impersonation {
    /// The insider's Hello got the real Welcome (so it held the key).
    joined: AtomicBool,
    /// Fake tasks the insider sent, and replies of any kind it got to them
    /// (but zenoh's own timeout).
    fake_tasks: AtomicUsize,
    fake_task_replies: AtomicUsize,
    /// Welcomes another listed worker's Hello got: the real one, the fake one.
    real_welcomes: AtomicUsize,
    fake_welcomes: AtomicUsize,
}

/// The real worker's name: its certificate's common name.
const REAL: &str = "ceilfarm-worker-1";

/// The study hash of the insider's fake Welcome.
const FAKE_HASH: &str = "f00d";

/// A listed worker certificate that joins (so holds the sweep's key), then
/// plays the coordinator: a fake Welcome on the Welcome keys, sealed fake
/// tasks (and plain puts) on the real worker's task key, until `stop`.
fn joined_insider(
    session: zenoh::Session,
    prefix: String,
    seen: Arc<Impersonation>,
    stop: Arc<AtomicBool>,
) {
    let s = &session;
    let remote = zenoh::sample::Locality::Remote;
    let Some(mac) = join_for_key(s, "insider", &stop) else { return };
    seen.joined.store(true, Ordering::Relaxed);
    let fake = protocol::ToWorker::Welcome {
        study_hash: FAKE_HASH.into(),
        model: protocol::ModelSpec {
            kind: "borehole".into(),
            options_json: "{}".into(),
            param_names: vec![],
            outputs: vec![],
        },
        key: SweepKey::from_bytes([1; KEY_BYTES]),
    };
    let fake = codec::encode(&fake).unwrap();
    let mut welcomes = Vec::new();
    for key in ["ceilfarm/*/welcome".to_string(), format!("{prefix}/welcome")] {
        let fake = fake.clone();
        let q = s
            .declare_queryable(key)
            .allowed_origin(remote)
            .callback(move |q| {
                let _ = q.reply(q.key_expr().clone(), fake.clone()).wait();
            })
            .wait()
            .unwrap();
        welcomes.push(q);
    }
    let mut seq = 1 << 40;
    while !stop.load(Ordering::Relaxed) {
        seq += 1;
        let task = protocol::ToWorker::Task(protocol::Task { id: TaskId(0), params: vec![0.5; 8] });
        let sealed = mac.seal(Direction::ToWorker, seq, &task).unwrap();
        for key in [format!("{prefix}/task/{REAL}"), format!("{prefix}/task/*")] {
            let _ = s.put(&key, sealed.clone()).wait();
            let replies = s
                .get(&key)
                .allowed_destination(remote)
                .payload(sealed.clone())
                .timeout(Duration::from_millis(200))
                .wait()
                .unwrap();
            seen.fake_tasks.fetch_add(1, Ordering::Relaxed);
            // zenoh closes an unanswered query with its own "Timeout" error.
            while let Ok(r) = replies.recv() {
                let timeout = r.result().is_err_and(|e| e.payload().to_bytes() == &b"Timeout"[..]);
                if !timeout {
                    seen.fake_task_replies.fetch_add(1, Ordering::Relaxed);
                }
            }
        }
    }
}

/// Another listed worker's Hellos, as a worker joins, until `stop`:
/// counts the real Welcomes and the insider's fake ones.
fn hello_probe(session: zenoh::Session, seen: Arc<Impersonation>, stop: Arc<AtomicBool>) {
    let hello = FromWorker::Hello {
        proto: protocol::PROTOCOL_VERSION,
        name: "probe".into(),
        threads: 1,
        study: None,
    };
    while !stop.load(Ordering::Relaxed) {
        let replies = session
            .get("ceilfarm/*/welcome")
            .payload(codec::encode(&hello).unwrap())
            .timeout(Duration::from_millis(300))
            .wait()
            .unwrap();
        while let Ok(r) = replies.recv() {
            let Ok(sample) = r.result() else { continue };
            if let Ok(protocol::ToWorker::Welcome { study_hash, .. }) =
                codec::decode(&sample.payload().to_bytes())
            {
                match study_hash == FAKE_HASH {
                    true => seen.fake_welcomes.fetch_add(1, Ordering::Relaxed),
                    false => seen.real_welcomes.fetch_add(1, Ordering::Relaxed),
                };
            }
        }
    }
}

fn config_of(ca: &LabCa, common_name: &str, connect: &str) -> String {
    valid_config_of(ca, common_name, connect, &Validity::from_now(1))
}

fn valid_config_of(ca: &LabCa, common_name: &str, connect: &str, validity: &Validity) -> String {
    let id: Identity = ca.issue(common_name, &[], validity).unwrap();
    worker_config(ca.cert_pem(), &id, connect)
}

#[test]
fn attacks_on_a_secured_sweep_are_refused_and_the_export_is_unchanged() {
    let started = Instant::now();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let study = study(d);
    // The unattacked run, in-process.
    let plain = d.join("plain.db");
    run_ok(&["run", study.to_str().unwrap(), "--store", plain.to_str().unwrap(), "--quiet"]);
    let want = export(&plain, d, "plain.csv");

    let port = free_port();
    let tls = format!("tls/127.0.0.1:{port}");
    let today = Validity::from_now(1);
    let lab = LabCa::new("test lab CA", &today).unwrap();
    let hosts = vec!["127.0.0.1".to_string(), "localhost".to_string()];
    let coordinator = lab.issue(COORDINATOR_NAME, &hosts, &today).unwrap();
    let listed: Vec<String> = (1..=4).map(|k| format!("ceilfarm-worker-{k}")).collect();
    let ccfg = coordinator_config(lab.cert_pem(), &coordinator, &tls, &listed);
    let ccfg = write(d, "coordinator.json5", &ccfg);
    let real = config_of(&lab, REAL, &tls);
    let wcfg = write(d, "worker-1.json5", &real);
    let impostor = config_of(&lab, "ceilfarm-worker-2", &tls);
    let impersonator = config_of(&lab, "ceilfarm-worker-3", &tls);
    let probe = config_of(&lab, "ceilfarm-worker-4", &tls);
    let unlisted = config_of(&lab, "ceilfarm-visitor", &tls);
    // Another CA's certificate bearing a listed worker's name.
    let wrong_ca = config_of(&LabCa::new("another CA", &today).unwrap(), "ceilfarm-worker-1", &tls);
    // A listed worker's certificate of the lab's CA, valid for a day a month ago.
    let month_ago = std::time::SystemTime::now() - Duration::from_secs(30 * 86_400);
    let lapsed = Validity { start: month_ago, days: 1 };
    let expired = valid_config_of(&lab, "ceilfarm-worker-1", &tls, &lapsed);

    // The real worker's configuration under another name stops at once.
    let misnamed = misnamed_worker(&wcfg, "real");
    assert!(misnamed.contains("--name real") && misnamed.contains(REAL), "{misnamed}");

    let store = d.join("attacked.db");
    let coordinator = Kill(
        Command::new(bin())
            .args(["run", study.to_str().unwrap(), "--store", store.to_str().unwrap()])
            .args(["--transport", "zenoh", "--zenoh-config", ccfg.to_str().unwrap()])
            .args(["--endpoint", &tls, "--quiet", "--json", "-v"])
            .stdout(Stdio::piped())
            .stderr(std::fs::File::create(d.join("coordinator.log")).unwrap())
            .spawn()
            .unwrap(),
    );
    std::thread::sleep(Duration::from_millis(500));

    // No credentials, no client certificate, another CA: no connection.
    let plain_tcp = client("{}", &format!("tcp/127.0.0.1:{port}"));
    assert!(plain_tcp.is_err(), "a plain TCP client connected");
    use base64::Engine;
    let ca64 = base64::engine::general_purpose::STANDARD.encode(lab.cert_pem());
    let no_cert = format!(
        r#"{{ "transport": {{ "link": {{ "tls": {{ "root_ca_certificate_base64": "{ca64}" }} }} }} }}"#
    );
    assert!(client(&no_cert, &tls).is_err(), "connected without a client certificate");
    assert!(client(&wrong_ca, &tls).is_err(), "a certificate of another CA connected");
    assert!(client(&expired, &tls).is_err(), "an expired certificate connected");

    // Connected attackers: one unlisted, one listed without the key.
    let stop = Arc::new(AtomicBool::new(false));
    let seen = Arc::new(Seen::default());
    let visitor = client(&unlisted, &tls).expect("a lab certificate connects (TLS is fine)");
    let (s2, st2) = (seen.clone(), stop.clone());
    let hash = coordinator::study::Study::load(&study).unwrap().hash();
    let prefix = format!("ceilfarm/{}", &hash[..16]);
    let visitor = std::thread::spawn(move || unlisted_attacker(visitor, prefix, s2, st2));
    let insider = client(&real, &tls).expect("the keyless copy connects");
    let (st3, real_key) = (stop.clone(), format!("ceilfarm/{}/task/{REAL}", &hash[..16]));
    let insider = std::thread::spawn(move || keyless_insider(insider, real_key, st3));
    let posing = Arc::new(Impostor::default());
    let impostor = client(&impostor, &tls).expect("the impostor connects");
    let (p6, st6, real_key) =
        (posing.clone(), stop.clone(), format!("ceilfarm/{}/task/{REAL}", &hash[..16]));
    let impostor = std::thread::spawn(move || {
        key_holding_impostor(impostor, "ceilfarm-worker-2", real_key, p6, st6)
    });
    let posed = Arc::new(Impersonation::default());
    let impersonator = client(&impersonator, &tls).expect("the joined insider connects");
    let (p4, st4, prefix) = (posed.clone(), stop.clone(), format!("ceilfarm/{}", &hash[..16]));
    let impersonator = std::thread::spawn(move || joined_insider(impersonator, prefix, p4, st4));
    let probe = client(&probe, &tls).expect("the probe connects");
    let (p5, st5) = (posed.clone(), stop.clone());
    let probe = std::thread::spawn(move || hello_probe(probe, p5, st5));
    std::thread::sleep(Duration::from_millis(500));

    let _worker = Kill(
        Command::new(bin())
            .args(["worker", "--transport", "zenoh", "--zenoh-config", wcfg.to_str().unwrap()])
            .args(["--threads", "2", "-v"])
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(d.join("worker.log")).unwrap())
            .spawn()
            .unwrap(),
    );
    let out = coordinator.wait_output(Duration::from_secs(30), d);
    stop.store(true, Ordering::Relaxed);
    visitor.join().unwrap();
    let insider_answered = insider.join().unwrap();
    impostor.join().unwrap();
    impersonator.join().unwrap();
    probe.join().unwrap();
    let attacked = export(&store, d, "attacked.csv");
    let forged_rows = String::from_utf8_lossy(&attacked).matches("12345").count();
    let count = |n: &AtomicUsize| n.load(Ordering::Relaxed);
    let (heard, forged) = (count(&posing.heard), count(&posing.forged));
    eprintln!(
        "worker-2's certificate on {REAL}'s task key: heard {heard} task queries, answered \
         {forged} with sealed forgeries; {forged_rows} forged values in the store"
    );

    let summary: serde_json::Value = serde_json::from_str(out.trim()).expect("summary");
    assert_eq!(summary["ok"], 40, "{summary}");
    assert_eq!(summary["failed"], 0, "{summary}");
    assert_eq!(summary["reissued"], 0, "{summary}");
    assert_eq!(seen.welcomes.load(Ordering::Relaxed), 0, "the unlisted attacker was welcomed");
    assert_eq!(seen.task_queries.load(Ordering::Relaxed), 0, "it heard task queries");
    assert!(seen.hellos_sent.load(Ordering::Relaxed) >= 2, "the attacker never tried");
    assert!(insider_answered > 0, "the insider heard no task query: the MAC was not tried");
    assert!(posing.joined.load(Ordering::Relaxed), "the impostor never held the sweep's key");
    assert_eq!(
        (heard, forged, forged_rows),
        (0, 0, 0),
        "another worker's certificate served {REAL}'s task key (task queries heard, sealed \
         forgeries answered, forged values stored)"
    );
    assert!(posed.joined.load(Ordering::Relaxed), "the insider never held the sweep's key");
    assert!(count(&posed.fake_tasks) > 0, "the insider sent no fake task");
    assert!(count(&posed.real_welcomes) > 0, "the probe's Hello never reached the coordinator");
    assert_eq!(count(&posed.fake_welcomes), 0, "a listed worker's Hello got the fake Welcome");
    assert_eq!(count(&posed.fake_task_replies), 0, "a worker answered the insider's fake task");
    assert_eq!(attacked, want, "exports differ");
    eprintln!(
        "attacks refused in {:.1} s; the insider answered {insider_answered} task queries with forgeries",
        started.elapsed().as_secs_f64()
    );
}

/// Starts the worker of configuration `config` as `--name name`; its
/// error message (it must stop within 10 s without connecting).
fn misnamed_worker(config: &Path, name: &str) -> String {
    let mut child = Kill(
        Command::new(bin())
            .args(["worker", "--transport", "zenoh", "--zenoh-config", config.to_str().unwrap()])
            .args(["--name", name])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    let deadline = Instant::now() + Duration::from_secs(10);
    while Instant::now() < deadline {
        if let Some(status) = child.0.try_wait().unwrap() {
            assert!(!status.success(), "a misnamed worker exited 0");
            let mut err = String::new();
            use std::io::Read;
            child.0.stderr.take().unwrap().read_to_string(&mut err).unwrap();
            return err;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    panic!("a worker named {name} with another worker's certificate was still running after 10 s")
}

trait WaitOutput {
    fn wait_output(self, limit: Duration, logs: &Path) -> String;
}

impl WaitOutput for Kill {
    fn wait_output(mut self, limit: Duration, logs: &Path) -> String {
        let deadline = Instant::now() + limit;
        while Instant::now() < deadline {
            if let Some(status) = self.0.try_wait().unwrap() {
                let mut out = String::new();
                use std::io::Read;
                self.0.stdout.take().unwrap().read_to_string(&mut out).unwrap();
                assert!(status.success(), "coordinator failed: {status}");
                return out;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let tail = |name: &str| {
            let text = std::fs::read_to_string(logs.join(name)).unwrap_or_default();
            let lines: Vec<&str> = text.lines().collect();
            lines[lines.len().saturating_sub(15)..].join("\n")
        };
        panic!(
            "the sweep did not finish within {limit:?}\ncoordinator:\n{}\nworker:\n{}",
            tail("coordinator.log"),
            tail("worker.log")
        );
    }
}
