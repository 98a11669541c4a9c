//! The model behind the schemes, its type erased: the schemes, the constrained code and the
//! driver's work run on `dyn ErasedModel`, so that they are compiled once, in this crate,
//! rather than once per model type in every program that runs a model (every scheme of
//! [`Scheme`](crate::Scheme) for each model, since the scheme is chosen at run time). A model's
//! evaluations cost tens of nanoseconds and more, against about one for the indirect call.
//!
//! The trait is not imported where models are used by their type, so that its methods never
//! compete with [`Model`]'s: a trait object's methods need no import.

use std::any::Any;

use crate::charts::Recentring;
use crate::error::{Failure, ModelError};
use crate::model::{DifferenceBuffers, Energy, Model, ModelInfo, Pose};

/// [`Model`]'s run-time methods, callable on a trait object, with its constants as methods.
#[allow(clippy::too_many_arguments)]
pub(crate) trait ErasedModel {
    fn nq(&self) -> usize;
    fn nu(&self) -> usize;
    fn nc(&self) -> usize;
    fn nframes(&self) -> usize;
    fn forward_dynamics_generated(&self) -> bool;
    fn info(&self) -> &'static ModelInfo;
    fn initial_state(&self, q: &mut [f64], qd: &mut [f64]);
    fn mass_matrix(&self, t: f64, q: &[f64], m: &mut [f64]);
    fn dynamics(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], m: &mut [f64], h: &mut [f64]);
    fn forward_dynamics(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        qdd: &mut [f64],
        pivots: &mut [f64],
    );
    fn inverse_dynamics(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        u: &[f64],
        tau: &mut [f64],
    );
    fn tangents(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        u: &[f64],
        k: &mut [f64],
        c: &mut [f64],
    ) -> Result<(), ModelError>;
    fn differenced_tangents(
        &self,
        t: f64,
        state: [&[f64]; 3],
        u: &[f64],
        out: [&mut [f64]; 2],
        work: DifferenceBuffers<'_>,
    ) -> usize;
    fn differenced_iteration_matrix(
        &self,
        t: f64,
        state: [&[f64]; 3],
        u: &[f64],
        weights: [f64; 2],
        a: &mut [f64],
        work: DifferenceBuffers<'_>,
    ) -> usize;
    fn complete_start(&self, t: f64, q: &mut [f64], qd: &mut [f64]) -> Result<(), Failure>;
    fn energy(&self, t: f64, q: &[f64], qd: &[f64]) -> Energy;
    fn constraints(&self, t: f64, q: &[f64], phi: &mut [f64]);
    fn constraint_jacobian(&self, t: f64, q: &[f64], b: &mut [f64]);
    fn constraint_rate(&self, t: f64, q: &[f64], phi_t: &mut [f64]);
    fn constraint_bias(&self, t: f64, q: &[f64], qd: &[f64], gamma: &mut [f64]);
    fn constraint_tangent(&self, t: f64, q: &[f64], lambda: &[f64], k: &mut [f64]);
    fn frames(&self, t: f64, q: &[f64], out: &mut [Pose]);
    fn take_failure(&self) -> Option<Failure>;
    fn user_evaluations(&self) -> usize;
    fn chart(&self, joint: usize) -> [[f64; 3]; 3];
    fn recentred(&self, moved: &[Recentring], q: &mut [f64], qd: &mut [f64]) -> bool;
    fn set_chart(&mut self, joint: usize, r: [[f64; 3]; 3]);
}

impl<M: Model> ErasedModel for M {
    fn nq(&self) -> usize {
        M::NQ
    }
    fn nu(&self) -> usize {
        M::NU
    }
    fn nc(&self) -> usize {
        M::NC
    }
    fn nframes(&self) -> usize {
        M::NFRAMES
    }
    fn forward_dynamics_generated(&self) -> bool {
        M::FORWARD_DYNAMICS_GENERATED
    }
    fn info(&self) -> &'static ModelInfo {
        Model::info(self)
    }
    fn initial_state(&self, q: &mut [f64], qd: &mut [f64]) {
        Model::initial_state(self, q, qd)
    }
    fn mass_matrix(&self, t: f64, q: &[f64], m: &mut [f64]) {
        Model::mass_matrix(self, t, q, m)
    }
    fn dynamics(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], m: &mut [f64], h: &mut [f64]) {
        Model::dynamics(self, t, q, qd, u, m, h)
    }
    fn forward_dynamics(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        qdd: &mut [f64],
        pivots: &mut [f64],
    ) {
        Model::forward_dynamics(self, t, q, qd, u, qdd, pivots)
    }
    fn inverse_dynamics(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        u: &[f64],
        tau: &mut [f64],
    ) {
        Model::inverse_dynamics(self, t, q, qd, qdd, u, tau)
    }
    fn tangents(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        u: &[f64],
        k: &mut [f64],
        c: &mut [f64],
    ) -> Result<(), ModelError> {
        Model::tangents(self, t, q, qd, qdd, u, k, c)
    }
    fn differenced_tangents(
        &self,
        t: f64,
        state: [&[f64]; 3],
        u: &[f64],
        out: [&mut [f64]; 2],
        work: DifferenceBuffers<'_>,
    ) -> usize {
        Model::differenced_tangents(self, t, state, u, out, work)
    }
    fn differenced_iteration_matrix(
        &self,
        t: f64,
        state: [&[f64]; 3],
        u: &[f64],
        weights: [f64; 2],
        a: &mut [f64],
        work: DifferenceBuffers<'_>,
    ) -> usize {
        Model::differenced_iteration_matrix(self, t, state, u, weights, a, work)
    }
    fn complete_start(&self, t: f64, q: &mut [f64], qd: &mut [f64]) -> Result<(), Failure> {
        Model::complete_start(self, t, q, qd)
    }
    fn energy(&self, t: f64, q: &[f64], qd: &[f64]) -> Energy {
        Model::energy(self, t, q, qd)
    }
    fn constraints(&self, t: f64, q: &[f64], phi: &mut [f64]) {
        Model::constraints(self, t, q, phi)
    }
    fn constraint_jacobian(&self, t: f64, q: &[f64], b: &mut [f64]) {
        Model::constraint_jacobian(self, t, q, b)
    }
    fn constraint_rate(&self, t: f64, q: &[f64], phi_t: &mut [f64]) {
        Model::constraint_rate(self, t, q, phi_t)
    }
    fn constraint_bias(&self, t: f64, q: &[f64], qd: &[f64], gamma: &mut [f64]) {
        Model::constraint_bias(self, t, q, qd, gamma)
    }
    fn constraint_tangent(&self, t: f64, q: &[f64], lambda: &[f64], k: &mut [f64]) {
        Model::constraint_tangent(self, t, q, lambda, k)
    }
    fn frames(&self, t: f64, q: &[f64], out: &mut [Pose]) {
        Model::frames(self, t, q, out)
    }
    fn take_failure(&self) -> Option<Failure> {
        Model::take_failure(self)
    }
    fn user_evaluations(&self) -> usize {
        Model::user_evaluations(self)
    }
    fn chart(&self, joint: usize) -> [[f64; 3]; 3] {
        Model::chart(self, joint)
    }
    fn recentred(&self, moved: &[Recentring], q: &mut [f64], qd: &mut [f64]) -> bool {
        Model::recentred(self, moved, q, qd)
    }
    fn set_chart(&mut self, joint: usize, r: [[f64; 3]; 3]) {
        Model::set_chart(self, joint, r)
    }
}

/// A model owned by the schemes: [`ErasedModel`], and its type back when the run ends.
pub(crate) trait OwnedModel: ErasedModel {
    /// The model as the schemes' code takes it.
    fn erased(&self) -> &dyn ErasedModel;
    fn erased_mut(&mut self) -> &mut dyn ErasedModel;
    fn as_any(&self) -> &dyn Any;
    fn into_any(self: Box<Self>) -> Box<dyn Any>;
    /// Each parameter whose value is not its default, set back to its default alone (where
    /// the parameters stay valid), `holds` asked of the model so changed; the parameters
    /// restored. The `(name, value, default)` of those for which it held, and whether every
    /// parameter was at its default.
    fn defaults_for_which(
        &mut self,
        holds: &mut dyn FnMut(&dyn ErasedModel) -> bool,
    ) -> (Vec<(&'static str, f64, f64)>, bool);
}

impl<M: Model + 'static> OwnedModel for M {
    fn erased(&self) -> &dyn ErasedModel {
        self
    }
    fn erased_mut(&mut self) -> &mut dyn ErasedModel {
        self
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn into_any(self: Box<Self>) -> Box<dyn Any> {
        self
    }
    fn defaults_for_which(
        &mut self,
        holds: &mut dyn FnMut(&dyn ErasedModel) -> bool,
    ) -> (Vec<(&'static str, f64, f64)>, bool) {
        crate::model::defaults_for_which(self, &mut |m: &M| holds(m))
    }
}
