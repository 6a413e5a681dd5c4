//! Smoothing of general half-edge meshes.
