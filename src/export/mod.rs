//! Exporters: the files made from one verified [`Assembly`](crate::assembly::Assembly).
//!
//! Each exporter reads the assembly (and the [catalog](crate::catalog)) and
//! writes to any [`std::io::Write`]; only the pipeline knows paths, and it
//! writes every file atomically.

pub mod partslist;
