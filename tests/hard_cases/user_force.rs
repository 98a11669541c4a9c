//! A user force that fails at t = 0.5 s (returns NaN, or an error): every scheme stops with
//! the typed error within one step of 0.5, and the trajectory it keeps holds no NaN. The
//! approach of `tests/efforts.rs`, on dpend with a horizontal push at the tip written in
//! Rust ([`mbs::WithEfforts`]).

use crate::support::{Work, all_finite, check_work, work};
use mbs::{Effort, Efforts, Failure, Model, Options, Scheme, WithEfforts, simulate};
use mbs_models::dpend::DoublePendulum;

/// A push of 2 N along x at the tip that becomes NaN, or an error, from t = 0.5 on.
struct Push {
    tip: usize,
    nan: bool,
}

impl Efforts for Push {
    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        if e.t < 0.5 {
            e.force_at_point(self.tip, [2.0, 0.0, 0.0]);
        } else if self.nan {
            e.force_at_point(self.tip, [f64::NAN, 0.0, 0.0]);
        } else {
            return Err("the force sensor is lost at t ≥ 0.5".into());
        }
        Ok(())
    }
}

#[test]
fn a_user_force_failing_at_half_a_second_stops_every_scheme_within_one_step() {
    let mut snapshots: Vec<(String, Work)> = Vec::new();
    for nan in [true, false] {
        for scheme in Scheme::all() {
            let model = DoublePendulum::default();
            let tip = model.info().point_index("tip").unwrap();
            let model = WithEfforts::new(model, Push { tip, nan });
            let o = if scheme.is_adaptive() {
                Options::adaptive(1.0, 1e-6)
            } else {
                Options::fixed(1.0, 1e-3)
            };
            let e = simulate(model, scheme, o).expect_err("fails at 0.5");
            let tr = &e.trajectory;
            let typed = match &e.kind {
                Failure::NonFinite { quantity, .. } => nan && *quantity == "user effort",
                Failure::UserEffort { t, message } => {
                    !nan && *t >= 0.5 && message.contains("sensor")
                }
                _ => false,
            };
            println!(
                "{:<10} {:<6} stopped at t = {:.6} (attempting h = {:.2e}), {} outputs: {}",
                scheme.name(),
                if nan { "NaN" } else { "Err" },
                e.t,
                e.h,
                tr.len(),
                e.kind
            );
            assert!(typed, "{} (NaN {nan}): {e}", scheme.name());
            assert!(all_finite(tr) && !tr.is_empty(), "{}", scheme.name());
            // within one step: the last accepted state is before 0.5, the attempted step
            // reaches it
            assert!(
                e.t < 0.5 && e.t + e.h >= 0.5 - 1e-12,
                "{}: t {} h {}",
                scheme.name(),
                e.t,
                e.h
            );
            assert_eq!(tr.t.last(), Some(&e.t), "kept up to the last accepted step");
            snapshots.push((
                format!("{} {}", scheme.name(), if nan { "NaN" } else { "Err" }),
                work(&e.stats),
            ));
        }
    }
    check_work(
        "user force",
        &snapshots,
        &[
            [499, 0, 0, 0, 573, 0, 0, 0, 0, 0, 0, 0],   // euler NaN
            [499, 0, 0, 0, 2072, 0, 0, 0, 0, 0, 0, 0],  // rk4 NaN
            [3742, 2, 1, 0, 9407, 0, 0, 0, 0, 0, 0, 0], // rkc NaN
            [18, 3, 1, 0, 131, 0, 0, 0, 0, 0, 0, 0],    // dopri5 NaN
            [2256, 2, 1, 0, 2, 2257, 9080, 0, 19, 9022, 9022, 2257], // newmark NaN
            [2467, 2, 1, 0, 2, 2468, 9908, 0, 19, 9850, 9850, 2468], // hht NaN
            [2694, 2, 1, 0, 2, 2695, 10724, 0, 19, 10666, 10666, 2695], // gen-alpha NaN
            [119, 13, 1, 0, 2, 120, 217, 0, 25, 141, 141, 120], // bdf NaN
            [366, 0, 1, 0, 2, 212, 2490, 0, 570, 1083, 717, 212], // radau3 NaN
            [24, 1, 1, 0, 2, 21, 282, 0, 46, 145, 60, 21], // radau5 NaN
            [499, 0, 0, 0, 501, 1, 2109, 0, 4, 2097, 2097, 1], // midpoint NaN
            [499, 0, 0, 0, 573, 0, 0, 0, 0, 0, 0, 0],   // euler Err
            [499, 0, 0, 0, 2072, 0, 0, 0, 0, 0, 0, 0],  // rk4 Err
            [3742, 2, 0, 0, 9407, 0, 0, 0, 0, 0, 0, 0], // rkc Err
            [18, 3, 0, 0, 131, 0, 0, 0, 0, 0, 0, 0],    // dopri5 Err
            [2256, 2, 1, 0, 2, 2257, 9080, 0, 19, 9022, 9022, 2257], // newmark Err
            [2467, 2, 1, 0, 2, 2468, 9908, 0, 19, 9850, 9850, 2468], // hht Err
            [2694, 2, 1, 0, 2, 2695, 10724, 0, 19, 10666, 10666, 2695], // gen-alpha Err
            [119, 13, 1, 0, 2, 120, 217, 0, 25, 141, 141, 120], // bdf Err
            [366, 0, 1, 0, 2, 212, 2490, 0, 570, 1083, 717, 212], // radau3 Err
            [24, 1, 1, 0, 2, 21, 282, 0, 46, 145, 60, 21], // radau5 Err
            [499, 0, 0, 0, 501, 1, 2109, 0, 4, 2097, 2097, 1], // midpoint Err
        ],
    );
}
