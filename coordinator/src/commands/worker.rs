//! `ceilfarm worker`: a stateless worker process for the iceoryx2 or zenoh
//! transport. It announces itself, runs any model kind, and on SIGTERM or
//! SIGINT finishes its running tasks, hands queued ones back and exits.

use anyhow::Result;
use clap::Args;
use coordinator::study::TransportKind;
use coordinator::transports::ZenohSecurity;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Arguments of `ceilfarm worker`.
#[derive(Args)]
pub struct WorkerArgs {
    /// Transport to serve.
    #[arg(long, value_enum)]
    pub transport: TransportKind,
    /// The coordinator's endpoint (zenoh, e.g. tls/10.0.0.5:7447; default
    /// the --zenoh-config file's, else tcp/127.0.0.1:7447) or the service
    /// prefix (iceoryx2).
    #[arg(long)]
    pub connect: Option<String>,
    /// zenoh's own JSON5 configuration: the worker's certificate and key and
    /// the lab's CA (`ceilfarm farm certs` writes one per worker).
    #[arg(long, value_name = "FILE")]
    pub zenoh_config: Option<std::path::PathBuf>,
    /// Tasks run at once (default 1).
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// Name announced to the coordinator (default: the common name of the
    /// --zenoh-config file's certificate, which it must equal if given;
    /// else host-pid).
    #[arg(long)]
    pub name: Option<String>,
    /// Serve only this study: a study file, or a prefix of its hash (as
    /// `ceilfarm status` prints it). Other sweeps refuse this worker.
    #[arg(long)]
    pub study: Option<String>,
}

/// Sets `stop` on SIGTERM or SIGINT; exits at once (status 0) while
/// `connected` is still false: a worker still connecting (zenoh's open
/// waits for the coordinator without end) holds no task to finish.
fn stop_on_signals(stop: Arc<AtomicBool>, connected: Arc<AtomicBool>) -> Result<()> {
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    std::thread::spawn(move || {
        rt.block_on(async move {
            use tokio::signal::unix::{signal, SignalKind};
            let (Ok(mut term), Ok(mut int)) =
                (signal(SignalKind::terminate()), signal(SignalKind::interrupt()))
            else {
                return;
            };
            tokio::select! {
                _ = term.recv() => {},
                _ = int.recv() => {},
            }
            if !connected.load(Ordering::SeqCst) {
                tracing::info!("stop requested before the link was up: exiting");
                std::process::exit(0);
            }
            tracing::info!("stop requested: finishing running tasks");
            stop.store(true, Ordering::Relaxed);
        })
    });
    Ok(())
}

/// Runs `ceilfarm worker`.
pub fn run(args: WorkerArgs) -> Result<()> {
    if args.threads == 0 {
        anyhow::bail!("--threads 0: expected at least 1");
    }
    let stop = Arc::new(AtomicBool::new(false));
    let connected = Arc::new(AtomicBool::new(false));
    stop_on_signals(stop.clone(), connected.clone())?;
    let security = ZenohSecurity { config: args.zenoh_config, insecure: false };
    let name =
        coordinator::transports::worker_name(args.transport, &security, args.name.as_deref())?
            .unwrap_or_else(|| format!("{}-{}", worker::run::host_name(), std::process::id()));
    let mut link =
        coordinator::transports::worker_link(args.transport, args.connect.as_deref(), &security)?;
    connected.store(true, Ordering::SeqCst);
    let study = args.study.as_deref().map(study_pin).transpose()?;
    let settings = worker::remote::RemoteSettings { name, threads: args.threads, study };
    worker::remote::serve_remote(link.as_mut(), &settings, &stop)?;
    Ok(())
}

/// The study hash prefix a worker is pinned to: a study file's hash, or the
/// hash prefix given as is.
fn study_pin(arg: &str) -> Result<String> {
    let path = std::path::Path::new(arg);
    if path.exists() {
        let study = coordinator::study::Study::load(path)?;
        return Ok(study.hash());
    }
    if arg.is_empty() || !arg.chars().all(|c| c.is_ascii_hexdigit()) {
        anyhow::bail!("--study {arg:?}: expected a study file or a hexadecimal study hash prefix");
    }
    Ok(arg.to_ascii_lowercase())
}
