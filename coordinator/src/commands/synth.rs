//! `ceilfarm synth SPEC.toml --out DIR`: simulate a test campaign and write
//! it as a measured-data bundle, the truth beside it.

use anyhow::Result;
use clap::Args as ClapArgs;
use std::path::PathBuf;

/// Arguments of `synth`.
#[derive(ClapArgs)]
pub struct Args {
    /// The campaign file (specimen, sensors, runs, truth, hidden effect, noise).
    pub spec: PathBuf,
    /// The bundle directory to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Where the answer goes (default: DIR.answer.json beside the bundle).
    #[arg(long)]
    pub answer: Option<PathBuf>,
}

/// Runs `synth`.
pub fn run(a: Args) -> Result<()> {
    let answer = a.answer.unwrap_or_else(|| {
        let mut name = a.out.file_name().unwrap_or_default().to_os_string();
        name.push(".answer.json");
        a.out.with_file_name(name)
    });
    let ans = coordinator::synth::synth_to_dir(&a.spec, &a.out, &answer, &mut |m| {
        eprintln!("synth: {m}")
    })?;
    println!(
        "wrote bundle {} to {} ({} hidden); answer in {}",
        ans.bundle,
        a.out.display(),
        ans.cause,
        answer.display()
    );
    Ok(())
}
