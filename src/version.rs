//! The version and the commit rtid was built from (`build.rs` records the commit).

/// The version and the commit built from: `0.1.0 (commit 1a2b3c4d5e6f)`.
pub const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (", env!("RTID_COMMIT"), ")");
