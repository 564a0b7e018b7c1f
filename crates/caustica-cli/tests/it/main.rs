//! The command line's integration tests, run against the real binary: one module a file, in one
//! test binary. `cargo test -p caustica-cli --test it MODULE::` runs one file's tests.

mod bad_input;
mod cli;
mod display;
mod formats;
mod physical;
mod summary;
