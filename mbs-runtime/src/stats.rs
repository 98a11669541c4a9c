//! Work counters of a simulation: what the scheme spent, so that work–precision comparisons
//! and regressions can be measured rather than assumed.

use serde::Serialize;
use std::fmt;

/// What a simulation did. Snapshot it in tests: a change that silently doubles the work fails.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Stats {
    /// accepted steps
    pub steps: usize,
    /// steps rejected by the local error test
    pub rejected_error: usize,
    /// steps rejected because Newton did not converge
    pub rejected_newton: usize,
    /// steps retried smaller because a user effort rejected a trial state
    /// ([`crate::Effort::reject`]; with Newton, also counted in `rejected_newton`)
    pub rejected_effort: usize,
    /// evaluations of M and h together (`Model::dynamics`)
    pub dynamics: usize,
    /// evaluations of qdd by the generated forward dynamics (`Model::forward_dynamics`:
    /// articulated bodies or sparse LᵀDL, neither M nor a dense factorisation)
    pub forward_dynamics: usize,
    /// evaluations of M alone
    pub mass_matrix: usize,
    /// evaluations of τ = M qdd − h (`Model::inverse_dynamics`)
    pub inverse_dynamics: usize,
    /// evaluations of the exact tangents K_t, C_t
    pub tangents: usize,
    /// evaluations of constraint functions (Φ, B, ∂Φ/∂t, γ or ∂(Bᵀλ)/∂q, each counted)
    pub constraints: usize,
    /// projections of a state onto Φ = 0, Φ̇ = 0 (or completions of dependent coordinates)
    pub projections: usize,
    /// changes of the independent coordinates (coordinate partitioning)
    pub repartitions: usize,
    /// calls of sampled controllers
    pub samples: usize,
    /// re-centrings of the charts of rotation joints (`Options::chart_switch`)
    pub chart_switches: usize,
    /// evaluations of user efforts (none yet: reserved for user force hooks)
    pub user_efforts: usize,
    /// evaluations of energy (for outputs)
    pub energy: usize,
    /// LU or Cholesky factorisations
    pub factorizations: usize,
    /// solves with a factorisation
    pub solves: usize,
    /// Cholesky factorisations of M made only to watch for a singular configuration
    /// (implicit schemes, at each iteration matrix that evaluates M, or at each accepted step
    /// of the Newmark family and BDF when their iteration matrices are finite differences of
    /// τ: `Options::singularity_tol`), and once at the start of an implicit scheme when the
    /// generated forward dynamics solved for the start's accelerations (the reference)
    pub condition_checks: usize,
    /// Cholesky factorisations of B Bᵀ made only to watch closed loops for a change point
    /// (after each accepted step of the index-3 and stabilized index-2 forms, one evaluation
    /// of B each, counted in `constraints`: `Options::singularity_tol`)
    pub loop_checks: usize,
    /// Newton iterations, all steps together
    pub newton_iterations: usize,
    /// smallest and largest accepted step
    pub h_min: f64,
    pub h_max: f64,
    /// for multistep schemes of variable order: steps taken at each order (index 0 = order 1)
    pub order_steps: Vec<usize>,
    /// DOPRI5's stiffness detection: how often h·|λ| stayed past its stability region for 15
    /// accepted steps in a row, and the time the first such run ended (the step was held by
    /// stability, not accuracy: an implicit scheme would take far fewer steps)
    pub stiff_detections: usize,
    pub stiff_from: Option<f64>,
    /// which components the local error test controls (nothing at fixed steps)
    pub error_test: ErrorTest,
    /// `Some(rtol')` when the user's rtol asked of the local error test a tolerance below the
    /// scheme's floor, which it held instead: the run then gives fewer digits than rtol, where
    /// a tighter rtol would otherwise have taken more steps (the Newmark family from rtol ≈
    /// 4e-8 on, its floor 10⁴ε, at index 3 from ≈ 2e-8, its floor 10³ε; RKC from ≈ 2e-9,
    /// BDF from ≈ 8e-11, their floors 100ε; Radau at index 3, its floor 10⁵ε, Radau5 from
    /// ≈ 4.5e-9, Radau3 from ≈ 3.8e-8)
    pub tolerance_floor: Option<f64>,
    /// the loosest rtol at which the scheme's local error test holds its floor rather than
    /// its transformation of rtol (adaptive steps of a scheme with a floor, `None` otherwise):
    /// a tighter rtol than this takes no more steps than it, so that no tighter run can
    /// measure the error of a run at it (global error control keeps its candidates at twice
    /// this rtol or above)
    pub floor_from: Option<f64>,
    /// accepted steps whose error test raised some component's weight atol' + rtol'·|y_i| to
    /// its rounding floor, 100ε times the largest entry of its kind (positions, velocities,
    /// multipliers): a component near zero beside large ones of its kind was tested at the
    /// digits rounding leaves it, not at the tolerance asked of it (the user's atol, or the
    /// scheme's transformation of it: RKC's local tolerance at rtol 1e-8 is 0.3·rtol^1.5 on
    /// atol too, below the rounding of a fast mechanism's slow components)
    pub floored_steps: usize,
    /// the coordinate (its position or velocity) or multiplier whose error test held the most
    /// accepted steps, and how many: what sets the step of an adaptive run (none at fixed
    /// steps)
    pub held_most: Option<crate::error::HeldMost>,
}

/// The components an adaptive scheme's local error test measures, so that a user knows what
/// `rtol` bought: at index 3 the velocities and multipliers are not controlled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub enum ErrorTest {
    /// fixed steps: no error test
    #[default]
    None,
    /// positions and velocities (and extra states)
    PositionsVelocities,
    /// positions only: the Newmark family's estimate h²(β − ⅙)(a₁ − a₀) except at index 2
    /// (at index 3 its part along the constraints), against rtol' = 0.3·rtol^1.5 (0.07·rtol^1.5
    /// at index 3) so that the global error follows rtol; velocities and multipliers are not
    /// tested (the velocities' error follows the positions' by the scheme's order 2, the
    /// multipliers' does not)
    Positions,

    /// positions, and the positions that the velocities' and multipliers' errors move in one
    /// step, h e_v + h² M_ii⁻¹(Bᵀe_λ)_i (Radau IIA at index 3; Hairer's RADAU5 weighs them by
    /// h and h² in their own units): the velocities' and multipliers' errors follow the step
    /// size; Radau5 maps rtol' = 3·rtol^(4/3) and Radau3 3·rtol^1.5 so that their velocities
    /// follow rtol (from 1e-4 to 1e-8 and 1e-6), and the multipliers follow rtol under neither
    PositionsScaledVelocities,
}

impl fmt::Display for ErrorTest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ErrorTest::None => "none (fixed steps)",
            ErrorTest::PositionsVelocities => "positions and velocities",
            ErrorTest::Positions => "positions only",

            ErrorTest::PositionsScaledVelocities => {
                "positions, and what the velocities' and multipliers' errors move them in a step"
            }
        })
    }
}

impl Stats {
    /// Evaluations of the model's equations of any kind (M+h, forward dynamics, M, τ,
    /// tangents).
    pub fn evaluations(&self) -> usize {
        self.dynamics
            + self.forward_dynamics
            + self.mass_matrix
            + self.inverse_dynamics
            + self.tangents
    }

    /// Adds the work of `other`: counters summed, the range of steps widened, the order
    /// histories summed (the work of several runs, as in global error control).
    pub fn add_work(&mut self, other: &Stats) {
        if other.steps > 0 {
            if self.steps == 0 {
                (self.h_min, self.h_max) = (other.h_min, other.h_max);
            } else {
                self.h_min = self.h_min.min(other.h_min);
                self.h_max = self.h_max.max(other.h_max);
            }
        }
        let sums = [
            (&mut self.steps, other.steps),
            (&mut self.rejected_error, other.rejected_error),
            (&mut self.rejected_newton, other.rejected_newton),
            (&mut self.dynamics, other.dynamics),
            (&mut self.forward_dynamics, other.forward_dynamics),
            (&mut self.mass_matrix, other.mass_matrix),
            (&mut self.inverse_dynamics, other.inverse_dynamics),
            (&mut self.tangents, other.tangents),
            (&mut self.constraints, other.constraints),
            (&mut self.projections, other.projections),
            (&mut self.repartitions, other.repartitions),
            (&mut self.samples, other.samples),
            (&mut self.chart_switches, other.chart_switches),
            (&mut self.user_efforts, other.user_efforts),
            (&mut self.energy, other.energy),
            (&mut self.factorizations, other.factorizations),
            (&mut self.solves, other.solves),
            (&mut self.condition_checks, other.condition_checks),
            (&mut self.loop_checks, other.loop_checks),
            (&mut self.newton_iterations, other.newton_iterations),
            (&mut self.stiff_detections, other.stiff_detections),
        ];
        for (a, b) in sums {
            *a += b;
        }
        if self.order_steps.len() < other.order_steps.len() {
            self.order_steps.resize(other.order_steps.len(), 0);
        }
        for (a, b) in self.order_steps.iter_mut().zip(&other.order_steps) {
            *a += b;
        }
        self.stiff_from = match (self.stiff_from, other.stiff_from) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
    }

    pub(crate) fn record_step(&mut self, h: f64) {
        if self.steps == 0 {
            self.h_min = h;
            self.h_max = h;
        } else {
            self.h_min = self.h_min.min(h);
            self.h_max = self.h_max.max(h);
        }
        self.steps += 1;
    }

    pub(crate) fn record_order(&mut self, order: usize) {
        if self.order_steps.len() < order {
            self.order_steps.resize(order, 0);
        }
        self.order_steps[order - 1] += 1;
    }
}

impl fmt::Display for Stats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "steps {} accepted, {} rejected by the error test, {} by Newton; h in [{:.3e}, {:.3e}]",
            self.steps, self.rejected_error, self.rejected_newton, self.h_min, self.h_max
        )?;
        writeln!(
            f,
            "evaluations: {} M+h, {} forward dynamics, {} M, {} τ, {} tangents, {} user efforts, {} energy",
            self.dynamics,
            self.forward_dynamics,
            self.mass_matrix,
            self.inverse_dynamics,
            self.tangents,
            self.user_efforts,
            self.energy
        )?;
        if self.samples > 0 {
            writeln!(f, "controllers: {} samples", self.samples)?;
        }
        if self.chart_switches > 0 {
            writeln!(
                f,
                "rotation joints: {} re-centrings of their charts",
                self.chart_switches
            )?;
        }
        if self.constraints > 0 {
            writeln!(
                f,
                "constraints: {} evaluations, {} projections, {} changes of partition",
                self.constraints, self.projections, self.repartitions
            )?;
        }
        write!(
            f,
            "linear algebra: {} factorisations, {} solves; {} Newton iterations",
            self.factorizations, self.solves, self.newton_iterations
        )?;
        if self.condition_checks > 0 {
            write!(
                f,
                "; {} Cholesky factorisations of M to watch its conditioning",
                self.condition_checks
            )?;
        }
        if self.loop_checks > 0 {
            write!(
                f,
                "; {} Cholesky factorisations of B Bᵀ to watch the loops",
                self.loop_checks
            )?;
        }
        if self.error_test != ErrorTest::None {
            write!(f, "\nerror test on: {}", self.error_test)?;
        }
        if let Some(floor) = self.tolerance_floor {
            let from = self
                .floor_from
                .map(|r| format!(", as at every rtol below {r:.1e}"))
                .unwrap_or_default();
            write!(
                f,
                "\nrtol asks more than this scheme's local error test holds: its tolerance stopped at its floor {floor:.1e}{from}, so expect fewer digits than rtol (radau5 with projection, its default, follows rtol further)"
            )?;
        }
        if let Some(h) = &self.held_most {
            write!(f, "\n{h}")?;
        }
        if self.floored_steps > 0 {
            write!(
                f,
                "\nin {} of {} steps the error test held a component at its rounding (100ε times the largest of its kind), below which the tolerance asked of it lies: it got the digits rounding leaves",
                self.floored_steps, self.steps
            )?;
        }
        if !self.order_steps.is_empty() {
            let orders: Vec<String> = self
                .order_steps
                .iter()
                .enumerate()
                .map(|(k, s)| format!("{}:{s}", k + 1))
                .collect();
            write!(f, "\nsteps per order: {}", orders.join(" "))?;
        }
        if let Some(t) = self.stiff_from {
            write!(
                f,
                "\nstiff from t = {} ({} detection{}): the step was held by stability, not accuracy; radau5 or bdf would take fewer",
                crate::error::short(t),
                self.stiff_detections,
                if self.stiff_detections == 1 { "" } else { "s" }
            )?;
        }
        Ok(())
    }
}
