//! Parquet export of a store: the same table as the CSV export (task id,
//! inputs, scalar outputs as nullable doubles, status and reason as UTF-8),
//! one row group, uncompressed. `pandas.read_parquet(path)` loads it.

use crate::export::ExportError;
use crate::store::{RunRow, RunStatus, Store};
use parquet::basic::{LogicalType, Repetition, Type as Physical};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::path::Path;
use std::sync::Arc;

fn pq_err(path: &Path) -> impl Fn(parquet::errors::ParquetError) -> ExportError + '_ {
    move |e| ExportError::Io {
        path: path.display().to_string(),
        source: std::io::Error::other(e.to_string()),
    }
}

fn column(
    name: &str,
    physical: Physical,
    rep: Repetition,
    text: bool,
) -> Result<Arc<Type>, parquet::errors::ParquetError> {
    let mut b = Type::primitive_type_builder(name, physical).with_repetition(rep);
    if text {
        b = b.with_logical_type(Some(LogicalType::String));
    }
    Ok(Arc::new(b.build()?))
}

/// Writes inputs and scalar outputs, one row per run, to a Parquet file.
pub fn export_parquet(store: &Store, out: &Path) -> Result<usize, ExportError> {
    let err = pq_err(out);
    let names = store.parameter_names()?;
    let outputs = store.scalar_names()?;
    let rows = store.rows()?;
    let mut fields =
        vec![column("task_id", Physical::INT64, Repetition::REQUIRED, false).map_err(&err)?];
    for n in &names {
        fields.push(column(n, Physical::DOUBLE, Repetition::REQUIRED, false).map_err(&err)?);
    }
    for n in &outputs {
        fields.push(column(n, Physical::DOUBLE, Repetition::OPTIONAL, false).map_err(&err)?);
    }
    for n in ["status", "reason"] {
        fields.push(column(n, Physical::BYTE_ARRAY, Repetition::REQUIRED, true).map_err(&err)?);
    }
    let schema =
        Arc::new(Type::group_type_builder("ceilfarm").with_fields(fields).build().map_err(&err)?);
    let file = std::fs::File::create(out)
        .map_err(|source| ExportError::Io { path: out.display().to_string(), source })?;
    let mut writer =
        SerializedFileWriter::new(file, schema, Arc::new(WriterProperties::builder().build()))
            .map_err(&err)?;
    let mut group = writer.next_row_group().map_err(&err)?;
    let mut index = 0;
    while let Some(mut col) = group.next_column().map_err(&err)? {
        write_column(&mut col, index, names.len(), &outputs, &rows).map_err(&err)?;
        col.close().map_err(&err)?;
        index += 1;
    }
    group.close().map_err(&err)?;
    writer.close().map_err(&err)?;
    Ok(rows.len())
}

fn write_column(
    col: &mut parquet::file::writer::SerializedColumnWriter<'_>,
    index: usize,
    n_params: usize,
    outputs: &[String],
    rows: &[RunRow],
) -> Result<(), parquet::errors::ParquetError> {
    let n_out = outputs.len();
    if index == 0 {
        let ids: Vec<i64> = rows.iter().map(|r| r.task.0 as i64).collect();
        col.typed::<Int64Type>().write_batch(&ids, None, None)?;
    } else if index <= n_params {
        let v: Vec<f64> = rows.iter().map(|r| r.params[index - 1]).collect();
        col.typed::<DoubleType>().write_batch(&v, None, None)?;
    } else if index <= n_params + n_out {
        let name = &outputs[index - n_params - 1];
        let present: Vec<Option<f64>> = rows.iter().map(|r| r.scalars.get(name).copied()).collect();
        let values: Vec<f64> = present.iter().flatten().copied().collect();
        let defs: Vec<i16> = present.iter().map(|p| i16::from(p.is_some())).collect();
        col.typed::<DoubleType>().write_batch(&values, Some(&defs), None)?;
    } else {
        let status = index == n_params + n_out + 1;
        let v: Vec<ByteArray> = rows
            .iter()
            .map(|r| {
                let (s, reason) = match &r.status {
                    Some(RunStatus::Ok) => ("ok", ""),
                    Some(RunStatus::Failed(why)) => ("failed", why.as_str()),
                    None => ("missing", ""),
                };
                ByteArray::from(if status { s } else { reason })
            })
            .collect();
        col.typed::<ByteArrayType>().write_batch(&v, None, None)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::Study;
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use protocol::{Outcome, Outputs, TaskId, TaskResult};

    #[test]
    fn parquet_round_trips_values_and_missing_outputs() {
        let dir = tempfile::tempdir().unwrap();
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../configs/ishigami.toml"
        ))
        .unwrap();
        let study = Study::parse(&text.replace("n = 1024", "n = 3"), Path::new("i.toml")).unwrap();
        let design = vec![vec![0.1, 0.2, 0.3], vec![0.4, 0.5, 0.6], vec![-1.0, 0.0, 1.0]];
        let mut store =
            Store::create(&dir.path().join("s.db"), &study, &design, &["y".into()]).unwrap();
        let ok = |id, y| TaskResult {
            id: TaskId(id),
            outcome: Outcome::Ok(Outputs { scalars: vec![("y".into(), y)], histories: vec![] }),
            wall_s: 0.0,
            host: "h".into(),
        };
        let failed = TaskResult {
            id: TaskId(1),
            outcome: Outcome::Failed { reason: "boom".into() },
            wall_s: 0.0,
            host: "h".into(),
        };
        store.record(&[ok(0, 1.5), failed, ok(2, -2.25)], 1, &Default::default()).unwrap();
        let out = dir.path().join("x.parquet");
        assert_eq!(export_parquet(&store, &out).unwrap(), 3);
        let reader = SerializedFileReader::new(std::fs::File::open(&out).unwrap()).unwrap();
        assert_eq!(reader.metadata().file_metadata().num_rows(), 3);
        let rows: Vec<String> =
            reader.get_row_iter(None).unwrap().map(|r| r.unwrap().to_string()).collect();
        assert!(
            rows[0].contains("x1: 0.1")
                && rows[0].contains("y: 1.5")
                && rows[0].contains("status: \"ok\""),
            "{}",
            rows[0]
        );
        assert!(rows[1].contains("y: null") && rows[1].contains("reason: \"boom\""), "{}", rows[1]);
        assert!(rows[2].contains("y: -2.25"), "{}", rows[2]);
    }
}
