//! The command line's parts: arguments, progress, and what it prints.

pub mod args;
pub mod print;
pub mod progress;
