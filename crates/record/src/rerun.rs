//! rerun's SDK under the names of the `rerun` facade crate, built from rerun's own `re_sdk` and
//! `re_sdk_types`: writing a `.rrd` needs neither the facade's catalog client nor its chunk store
//! and analytics (about 50 crates of the cold build). Files are the same rerun 0.36.3 recordings.

pub use re_sdk::*;
pub use re_sdk_types::archetypes::*;
pub use re_sdk_types::components;
pub use re_sdk_types::components::Color;

/// The crates behind the SDK (the recording decoder reads `.rrd` back).
pub mod external {
    pub use re_log_encoding;
}
