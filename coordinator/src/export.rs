//! Export of a store: one CSV row per run (task id, inputs, scalar outputs,
//! status), in task order, floats in shortest round-trip form; time
//! histories as one CSV per run. `pandas.read_csv(path)` loads it.

use crate::store::{RunStatus, Store, StoreError};
use crate::study::format_value;
use std::io::Write;
use std::path::Path;

/// Why an export failed.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The store could not be read.
    #[error(transparent)]
    Store(#[from] StoreError),
    /// Writing failed.
    #[error("{path}: {source}")]
    Io {
        /// The output file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// CSV writing failed.
    #[error("{path}: {source}")]
    Csv {
        /// The output file.
        path: String,
        /// The cause.
        source: csv::Error,
    },
}

/// Writes inputs and scalar outputs, one row per run, to a CSV file.
pub fn export_csv(store: &Store, out: &Path) -> Result<usize, ExportError> {
    let csv_err = |source| ExportError::Csv { path: out.display().to_string(), source };
    let names = store.parameter_names()?;
    let outputs = store.scalar_names()?;
    let rows = store.rows()?;
    let mut w = csv::Writer::from_path(out).map_err(csv_err)?;
    let mut header = vec!["task_id".to_string()];
    header.extend(names.iter().cloned());
    header.extend(outputs.iter().cloned());
    header.extend(["status".to_string(), "reason".to_string()]);
    w.write_record(&header).map_err(csv_err)?;
    for row in &rows {
        let mut rec = vec![row.task.0.to_string()];
        rec.extend(row.params.iter().map(|v| format_value(*v)));
        rec.extend(
            outputs
                .iter()
                .map(|o| row.scalars.get(o).map(|v| format_value(*v)).unwrap_or_default()),
        );
        let (status, reason) = match &row.status {
            Some(RunStatus::Ok) => ("ok", String::new()),
            Some(RunStatus::Failed(r)) => ("failed", r.clone()),
            None => ("missing", String::new()),
        };
        rec.push(status.into());
        rec.push(reason);
        w.write_record(&rec).map_err(csv_err)?;
    }
    w.flush().map_err(|source| ExportError::Io { path: out.display().to_string(), source })?;
    Ok(rows.len())
}

/// Writes each run's time histories as `DIR/task_<id>_<name>.csv` (`t_s`, then channels).
pub fn export_histories(store: &Store, dir: &Path) -> Result<usize, ExportError> {
    let io = |p: &Path| {
        let path = p.display().to_string();
        move |source| ExportError::Io { path: path.clone(), source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let mut files = 0;
    for row in store.rows()? {
        for h in store.histories(row.task)? {
            let path = dir.join(format!("task_{:06}_{}.csv", row.task.0, h.name));
            let mut f = std::io::BufWriter::new(std::fs::File::create(&path).map_err(io(&path))?);
            writeln!(f, "t_s,{}", h.channels.join(",")).map_err(io(&path))?;
            let width = h.channels.len().max(1);
            for (k, chunk) in h.data.chunks_exact(width).enumerate() {
                let vals: Vec<String> = chunk.iter().map(|v| format_value(*v)).collect();
                writeln!(f, "{},{}", format_value(k as f64 * h.dt_s), vals.join(","))
                    .map_err(io(&path))?;
            }
            f.flush().map_err(io(&path))?;
            files += 1;
        }
    }
    Ok(files)
}
