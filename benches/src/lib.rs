//! Criterion benchmarks of polylidar-rs.
