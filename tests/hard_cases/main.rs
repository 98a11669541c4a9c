//! Hard cases that must stay numerically stable: each case
//! asserts stability or the typed error, prints its figures and snapshots its work counters
//! as `tests/work_counters.rs` does. `cargo test --release --test hard_cases -- --nocapture`
//! prints the tables.
#![allow(clippy::needless_range_loop)]

#[path = "../common/mod.rs"]
mod common;
#[path = "../common/quoted.rs"]
mod quoted;
mod support;

mod chain16;
mod dpend_drift;
mod fourbar_start;
mod seed2dof_long_run;
mod singular;
mod springpend;
mod structural;
mod tumble;
mod user_force;
