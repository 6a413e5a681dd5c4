//! [`GpuSmoother`] when the crate is built without the `gpu` feature: the type exists so
//! that code using it compiles either way, but it cannot be created.

use std::convert::Infallible;

use opc_mesh::OrganizedPointCloud;

use crate::{BilateralOptions, LaplacianOptions, SlotNormals, SmoothError};

/// The GPU smoother; this build lacks the `gpu` cargo feature, so [`GpuSmoother::new`]
/// always returns [`SmoothError::GpuFeatureDisabled`].
#[derive(Debug)]
pub struct GpuSmoother {
    never: Infallible,
}

impl GpuSmoother {
    /// Always [`SmoothError::GpuFeatureDisabled`] in this build.
    ///
    /// # Errors
    /// Always.
    pub fn new() -> Result<Self, SmoothError> {
        Err(SmoothError::GpuFeatureDisabled)
    }

    /// One line naming the adapter (never called: no value of this type exists).
    pub fn adapter_summary(&self) -> String {
        match self.never {}
    }

    /// The Laplacian filter on the GPU (never called: no value of this type exists).
    ///
    /// # Errors
    /// None can occur.
    pub fn laplacian(
        &mut self,
        _cloud: &OrganizedPointCloud,
        _options: &LaplacianOptions,
    ) -> Result<OrganizedPointCloud, SmoothError> {
        match self.never {}
    }

    /// The per-pixel Laplacian filter on the GPU (never called: no value of this type
    /// exists).
    ///
    /// # Errors
    /// None can occur.
    pub fn laplacian_per_pixel(
        &mut self,
        _cloud: &OrganizedPointCloud,
        _options: &LaplacianOptions,
        _passes: &[u8],
    ) -> Result<OrganizedPointCloud, SmoothError> {
        match self.never {}
    }

    /// The Laplacian and bilateral filters on the GPU in one go (never called: no value
    /// of this type exists).
    ///
    /// # Errors
    /// None can occur.
    pub fn laplacian_then_bilateral<R>(
        &mut self,
        _cloud: &OrganizedPointCloud,
        _laplacian: &LaplacianOptions,
        _passes: Option<&[u8]>,
        _bilateral: &BilateralOptions,
        _between: impl FnOnce(&OrganizedPointCloud) -> R,
    ) -> Result<(OrganizedPointCloud, R, SlotNormals), SmoothError> {
        match self.never {}
    }

    /// The bilateral filter on the GPU (never called: no value of this type exists).
    ///
    /// # Errors
    /// None can occur.
    pub fn bilateral(
        &mut self,
        _cloud: &OrganizedPointCloud,
        _options: &BilateralOptions,
    ) -> Result<SlotNormals, SmoothError> {
        match self.never {}
    }
}

impl crate::Smoother for GpuSmoother {
    fn laplacian(
        &mut self,
        _cloud: &OrganizedPointCloud,
        _options: &LaplacianOptions,
    ) -> Result<OrganizedPointCloud, SmoothError> {
        match self.never {}
    }

    fn bilateral(
        &mut self,
        _cloud: &OrganizedPointCloud,
        _options: &BilateralOptions,
    ) -> Result<SlotNormals, SmoothError> {
        match self.never {}
    }
}

/// Always 0: this build has no GPU backend; see [`crate::adapter_requests`].
pub fn adapter_requests() -> u64 {
    0
}
