//! A sweep's table as Parquet (feature `parquet`): `results.parquet` beside `results.csv`,
//! written when every run is in the table (a complete sweep, a merge).
//!
//! Columns keep their names; `status`, `failure` and `message` are UTF-8 strings, every other
//! column gets the narrowest type its fields all read as: 64-bit integers (`run`, `steps`, …),
//! doubles (values, metrics, times; `NaN` and `inf` included; also a column with no value at
//! all) or strings (scheme names); an empty field is null. Rows
//! are written in row groups of [`ROW_GROUP`], so memory stays bounded by one group.

use super::SweepError;
use ::parquet::basic::{Compression, LogicalType, Repetition, Type as Physical};
use ::parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use ::parquet::file::properties::WriterProperties;
use ::parquet::file::writer::SerializedFileWriter;
use ::parquet::schema::types::Type;
use std::path::Path;
use std::sync::Arc;

/// Rows per row group.
pub const ROW_GROUP: usize = 65_536;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Int,
    Float,
    Text,
}

/// Writes the CSV table `csv` as the Parquet file `out`; returns the number of rows.
pub fn write(csv: &Path, out: &Path) -> Result<usize, SweepError> {
    let bad = |path: &Path, reason: String| SweepError::Table {
        path: path.to_path_buf(),
        reason,
    };
    let reader = || csv::Reader::from_path(csv).map_err(|e| bad(csv, e.to_string()));
    // pass 1: the type of every column
    let mut r = reader()?;
    let names: Vec<String> = r
        .headers()
        .map_err(|e| bad(csv, e.to_string()))?
        .iter()
        .map(String::from)
        .collect();
    if names.is_empty() {
        return Err(bad(csv, "no header: the table is empty".into()));
    }
    // the failure's columns are text even when every run succeeded
    let mut kinds: Vec<Kind> = names
        .iter()
        .map(|n| match n.as_str() {
            "status" | "failure" | "message" => Kind::Text,
            _ => Kind::Int,
        })
        .collect();
    let mut seen = vec![false; names.len()];
    for rec in r.records() {
        let rec = rec.map_err(|e| bad(csv, e.to_string()))?;
        for ((k, field), seen) in kinds.iter_mut().zip(rec.iter()).zip(&mut seen) {
            if field.is_empty() {
                continue;
            }
            *seen = true;
            if *k == Kind::Int && field.parse::<i64>().is_err() {
                *k = Kind::Float;
            }
            if *k == Kind::Float && field.parse::<f64>().is_err() {
                *k = Kind::Text;
            }
        }
    }
    // a column without a value (a metric of runs that all failed) is a column of numbers
    for (k, seen) in kinds.iter_mut().zip(&seen) {
        if *k == Kind::Int && !seen {
            *k = Kind::Float;
        }
    }
    let fields = names
        .iter()
        .zip(&kinds)
        .map(|(name, kind)| {
            let (physical, logical) = match kind {
                Kind::Int => (Physical::INT64, None),
                Kind::Float => (Physical::DOUBLE, None),
                Kind::Text => (Physical::BYTE_ARRAY, Some(LogicalType::String)),
            };
            Type::primitive_type_builder(name, physical)
                .with_repetition(Repetition::OPTIONAL)
                .with_logical_type(logical)
                .build()
                .map(Arc::new)
        })
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| bad(out, e.to_string()))?;
    let schema = Type::group_type_builder("sweep")
        .with_fields(fields)
        .build()
        .map_err(|e| bad(out, e.to_string()))?;
    let props = WriterProperties::builder()
        .set_compression(Compression::SNAPPY)
        .build();
    let file = std::fs::File::create(out).map_err(|source| SweepError::Io {
        path: out.to_path_buf(),
        source,
    })?;
    let mut writer = SerializedFileWriter::new(file, Arc::new(schema), Arc::new(props))
        .map_err(|e| bad(out, e.to_string()))?;

    // pass 2: row groups
    let mut rows = 0;
    let mut group: Vec<Vec<String>> = vec![Vec::new(); names.len()];
    let mut records = reader()?.into_records();
    loop {
        let rec = records
            .next()
            .transpose()
            .map_err(|e| bad(csv, e.to_string()))?;
        if let Some(rec) = &rec {
            for (column, field) in group.iter_mut().zip(rec.iter()) {
                column.push(field.to_string());
            }
            rows += 1;
        }
        let full = group[0].len() == ROW_GROUP;
        if (full || rec.is_none()) && !group[0].is_empty() {
            write_group(&mut writer, &group, &kinds).map_err(|e| bad(out, e.to_string()))?;
            group.iter_mut().for_each(Vec::clear);
        }
        if rec.is_none() {
            break;
        }
    }
    writer.close().map_err(|e| bad(out, e.to_string()))?;
    Ok(rows)
}

fn write_group(
    writer: &mut SerializedFileWriter<std::fs::File>,
    group: &[Vec<String>],
    kinds: &[Kind],
) -> ::parquet::errors::Result<()> {
    let mut rg = writer.next_row_group()?;
    let mut j = 0;
    while let Some(mut col) = rg.next_column()? {
        let fields = &group[j];
        let defs: Vec<i16> = fields.iter().map(|f| i16::from(!f.is_empty())).collect();
        let present = fields.iter().filter(|f| !f.is_empty());
        match kinds[j] {
            Kind::Int => {
                let v: Vec<i64> = present.map(|f| f.parse().unwrap_or(0)).collect();
                col.typed::<Int64Type>()
                    .write_batch(&v, Some(&defs), None)?;
            }
            Kind::Float => {
                let v: Vec<f64> = present.map(|f| f.parse().unwrap_or(f64::NAN)).collect();
                col.typed::<DoubleType>()
                    .write_batch(&v, Some(&defs), None)?;
            }
            Kind::Text => {
                let v: Vec<ByteArray> = present.map(|f| ByteArray::from(f.as_str())).collect();
                col.typed::<ByteArrayType>()
                    .write_batch(&v, Some(&defs), None)?;
            }
        }
        col.close()?;
        j += 1;
    }
    rg.close()?;
    Ok(())
}
