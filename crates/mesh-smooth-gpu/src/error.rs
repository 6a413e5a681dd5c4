//! The error type of every filter in this crate.

/// Why a filter could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SmoothError {
    /// The kernel size is even, below 3 or above [`crate::MAX_KERNEL`].
    #[error("kernel size must be odd, from 3 to 15 (mesh_smooth_gpu::MAX_KERNEL), got {kernel}")]
    InvalidKernel {
        /// Kernel size given.
        kernel: u32,
    },
    /// A numeric parameter is out of its range.
    #[error("parameter {name} = {value} is invalid: {reason}")]
    InvalidParameter {
        /// Parameter name as in the options struct.
        name: &'static str,
        /// Value given.
        value: f64,
        /// What the value must satisfy.
        reason: &'static str,
    },
    /// A triangle of a half-edge mesh uses a vertex with a NaN or infinite coordinate.
    #[error("triangle {triangle} uses vertex {vertex}, which has a non-finite coordinate")]
    NonFiniteVertex {
        /// The offending vertex.
        vertex: u32,
        /// A triangle that uses it.
        triangle: usize,
    },
    /// A triangle of a half-edge mesh indexes a vertex that does not exist.
    #[error("triangle {triangle} uses vertex {vertex}, but the mesh has {num_vertices} vertices")]
    VertexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The vertex index it holds.
        vertex: u32,
        /// Number of vertices in the mesh.
        num_vertices: usize,
    },
    /// Filtered normals cannot be given to a mesh whose triangle count does not match.
    #[error(
        "{present} triangles exist in the implicit mesh but the target has {mesh_triangles}; \
         was it meshed from the same cloud?"
    )]
    TriangleCountMismatch {
        /// Present slots in the filtered normals.
        present: usize,
        /// Triangles in the target mesh.
        mesh_triangles: usize,
    },
    /// A triangle map does not fit the filtered normals.
    #[error("triangle map entry {slot} is invalid: {reason}")]
    BadTriangleMap {
        /// Slot (global triangle id) whose entry is wrong.
        slot: usize,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A [`GpuSmoother`](crate::GpuSmoother) was asked for, but the crate was built without
    /// its `gpu` feature.
    #[error("the GPU backend needs mesh-smooth-gpu built with the `gpu` cargo feature")]
    GpuFeatureDisabled,
    /// No GPU adapter (hardware or software driver) could be found.
    #[error(
        "no GPU adapter found ({reason}); install a Vulkan driver (e.g. Mesa's lavapipe, \
         Debian package mesa-vulkan-drivers) or use a CPU backend"
    )]
    NoAdapter {
        /// What wgpu reported.
        reason: String,
    },
    /// An adapter was found but refused to create a device.
    #[error("the GPU adapter refused to create a device: {reason}")]
    RequestDevice {
        /// What wgpu reported.
        reason: String,
    },
    /// The cloud needs a GPU buffer larger than the device allows.
    #[error("the cloud needs a {needed}-byte GPU buffer but the device allows at most {limit}")]
    CloudTooLargeForGpu {
        /// Bytes needed for the largest buffer.
        needed: u64,
        /// The device's storage-buffer binding limit.
        limit: u64,
    },
    /// The cloud has more rows or columns than one dispatch can cover.
    #[error("a {rows} × {cols} cloud exceeds the device's dispatch size of {max_side} per side")]
    GridTooLargeForGpu {
        /// Rows of the cloud.
        rows: usize,
        /// Columns of the cloud.
        cols: usize,
        /// Largest side the device can dispatch.
        max_side: usize,
    },
    /// The GPU failed while running or reading back the result.
    #[error("GPU execution failed: {reason}")]
    Gpu {
        /// What wgpu reported.
        reason: String,
    },
    /// The filtered points did not make a cloud of the input's shape.
    #[error("the filtered cloud is invalid: {0}")]
    Cloud(#[from] opc_mesh::OpcError),
}
