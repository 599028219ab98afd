//! A worker still connecting (zenoh's open waits for a coordinator without
//! end) exits promptly on SIGTERM (issue 56: it ignored it for 10 minutes).

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[test]
fn a_worker_waiting_for_its_coordinator_exits_on_sigterm() {
    // A port nobody listens on: the worker keeps trying to connect.
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let mut child = Command::new(env!("CARGO_BIN_EXE_ceilfarm"))
        .args(["worker", "--transport", "zenoh", "--connect", &format!("tcp/127.0.0.1:{port}")])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    assert!(child.try_wait().unwrap().is_none(), "the worker stopped before the signal");
    let sent = Instant::now();
    let kill = Command::new("kill").args(["-TERM", &child.id().to_string()]).status().unwrap();
    assert!(kill.success());
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if sent.elapsed() > Duration::from_secs(5) {
            let _ = child.kill();
            panic!("the worker ignored SIGTERM for 5 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    eprintln!("worker exited {status} {:.0} ms after SIGTERM", sent.elapsed().as_secs_f64() * 1e3);
    assert!(status.success(), "{status}");
}
