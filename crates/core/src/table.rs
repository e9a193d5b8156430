//! A Parquet table's row type: the one place its columns are written down (drapelab-record traces
//! the schema from it with `serde_arrow`; `drapelab tables` lists every table for the README).

/// A row of a table. Each field of the `serde` struct is a column: its name (units in it) is the
/// column's, `Option` makes it nullable, a unit-only enum is a string.
pub trait Table: serde::Serialize + serde::de::DeserializeOwned {
    /// The table's usual file name, e.g. `benchmark.parquet`.
    const FILE: &'static str;
    /// What one row is, in a line.
    const ROW: &'static str;
}
