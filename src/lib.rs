//! mbs: multibody dynamics from CAGeM-style kinematic chains.
pub use mbs_macros::multibody;
pub use mbs_runtime::*;

#[doc(hidden)]
pub mod __private {
    pub use serde;
}
