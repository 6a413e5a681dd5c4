//! What the GPU tests of the facade share.
#![allow(clippy::panic)]

use polylidar::{Extraction, PolylidarError};

/// The result of a run with GPU smoothing, or `None` (skipped, reason printed) where it
/// failed for want of a usable adapter outside CI; under CI (`CI=true`) that is a
/// failure, as is any other error.
pub fn gpu_run(result: Result<Extraction, PolylidarError>, what: &str) -> Option<Extraction> {
    match result {
        Ok(e) => Some(e),
        Err(PolylidarError::Smooth(e)) => {
            assert!(
                !test_fixtures::in_ci(),
                "{what}: no usable GPU adapter under CI=true: {e}; run .ci/install-gpu-deps.sh"
            );
            test_fixtures::record_skip(&format!("no GPU adapter ({e})"));
            None
        }
        Err(e) => panic!("{what}: GPU run failed: {e}"),
    }
}
