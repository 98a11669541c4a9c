//! The chains and arms of the scaling benchmark that `mbs-models` lacks: planar chains of 2,
//! 4, 16 and 32 bars and spatial arms of 12 and 24 joints (shapes in `shapes.rs`). The
//! 16-bar chain and the 12-joint arm also have the batch functions (`option batch;`) that
//! `batch.rs` measures.

include!("shapes.rs");

chain!(Chain2, 2);
chain!(Chain4, 4);
chain!(Chain16, 16, batch);
chain!(Chain32, 32);
arm!(Arm3d12, 12, 5, 11, 10, batch);
arm!(Arm3d24, 24, 11, 23, 22);
