//! Parameter sensitivities of statics: how an equilibrium moves with the parameters the model
//! marks `sensitive` (`param k = 1e4 sensitive;`), from the generated ∂τ/∂p.
//!
//! At an equilibrium τ(q, 0, 0, p) = 0 (τ = M qdd − h, so −h at rest); differentiating along
//! the equilibria, K dq/dp + ∂τ/∂p = 0 with K = ∂τ/∂q the stiffness, hence
//! dq/dp = −K⁻¹ ∂τ/∂p over the free coordinates (locked ones stay where they are). One
//! factorisation of K and one evaluation of ∂τ/∂p give every column, exact when K is (a model
//! with `option tangents;`), else to the accuracy of K's central differences.

use super::statics::{Equilibrium, StaticsOptions, stiffness};
use super::{AnalysisError, check};
use crate::error::Failure;
use crate::linalg::Lu;
use crate::model::Model;

/// dq/dp at an equilibrium: one column per sensitive parameter.
#[derive(Clone, Debug, serde::Serialize)]
pub struct StaticSensitivity {
    /// the sensitive parameters, the columns
    pub params: Vec<&'static str>,
    /// coordinate names, the rows
    pub dofs: Vec<String>,
    /// ∂q_eq/∂p, NQ × NS column-major (0 on locked coordinates)
    pub dq_dp: Vec<f64>,
}

impl StaticSensitivity {
    /// ∂q_i/∂p for coordinate `i` and the parameter named `param`.
    pub fn get(&self, i: usize, param: &str) -> Option<f64> {
        let j = self.params.iter().position(|p| *p == param)?;
        self.dq_dp.get(i + self.dofs.len() * j).copied()
    }
}

/// How the equilibrium `eq` (found with `options`, whose time, inputs, locked coordinates
/// and stiffness setting it reuses) moves with each sensitive parameter of `model`.
/// Models with constraints are refused (their equilibria move on the constraint manifold,
/// not handled yet).
pub fn static_sensitivity<M: Model + Clone>(
    model: &M,
    eq: &Equilibrium,
    options: &StaticsOptions,
) -> Result<StaticSensitivity, AnalysisError> {
    let n = M::NQ;
    let ns = M::SENSITIVE.len();
    let refuse = |reason: &'static str| {
        AnalysisError::from(Failure::InvalidOption {
            name: "model",
            value: model.info().name.to_string(),
            reason,
        })
    };
    if ns == 0 {
        return Err(refuse(
            "it has no sensitive parameters: mark them, `param k = 1e4 sensitive;`",
        ));
    }
    if M::NC > 0 {
        return Err(refuse(
            "its equilibria move on its constraints: static sensitivities of closed loops are not available yet",
        ));
    }
    // q is read in the equilibrium's charts
    let mut m = model.clone();
    for (j, r) in eq.charts.iter().enumerate() {
        m.set_chart(j, *r);
    }
    let u = options.u.clone().unwrap_or_else(|| vec![0.0; M::NU]);
    let zero = vec![0.0; n];
    let mut dtau = vec![0.0; n * ns];
    m.parameter_tangents(options.t, &eq.q, &zero, &zero, &u, &mut dtau)
        .map_err(|e| refuse(crate::integrators::model_error_reason(&e)))?;
    check(&m, "∂τ/∂p", &dtau)?;
    let mut k = vec![0.0; n * n];
    stiffness(&m, options.t, &eq.q, &u, options.stiffness, &mut k)?;
    let free: Vec<usize> = (0..n).filter(|i| !options.locked.contains(i)).collect();
    let nf = free.len();
    let mut lu = Lu::<f64>::new(nf);
    {
        let a = lu.matrix_mut();
        for (c, &j) in free.iter().enumerate() {
            for (r, &i) in free.iter().enumerate() {
                a[r + nf * c] = k[i + n * j];
            }
        }
    }
    lu.factor().map_err(|_| {
        refuse("its stiffness is singular at the equilibrium over the free coordinates (a neutral direction): lock the coordinates without stiffness")
    })?;
    let mut dq_dp = vec![0.0; n * ns];
    let mut b = vec![0.0; nf];
    for p in 0..ns {
        for (r, &i) in free.iter().enumerate() {
            b[r] = -dtau[i + n * p];
        }
        lu.solve(&mut b);
        for (r, &i) in free.iter().enumerate() {
            dq_dp[i + n * p] = b[r];
        }
    }
    check(&m, "∂q/∂p", &dq_dp)?;
    let info = m.info();
    Ok(StaticSensitivity {
        params: M::SENSITIVE.to_vec(),
        dofs: (0..n).map(|i| info.dof_label(i).to_string()).collect(),
        dq_dp,
    })
}
