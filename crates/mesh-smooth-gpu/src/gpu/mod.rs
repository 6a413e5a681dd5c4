//! The wgpu backend (cargo feature `gpu`): WGSL compute shaders that mirror the CPU
//! kernels on `f32` buffers.
//!
//! Shaped like wgpu's `hello_compute` / `repeated_compute` examples: a thin constructor
//! ([`GpuSmoother::new`]) finds an adapter and a device; everything else takes the device
//! and queue ([`GpuSmoother::from_device`]). Pipelines are compiled once; the buffers of
//! the last cloud shape are kept and reused. A call uploads the cloud once, runs every
//! iteration on the device (ping-pong buffers) and reads the result back once.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;

use opc_mesh::OrganizedPointCloud;

use crate::grid::num_slots;
use crate::{BilateralOptions, LaplacianOptions, SlotNormals, SmoothError};

/// Invocations per workgroup along x and y (matches `@workgroup_size(16, 16, 1)`).
const WORKGROUP_SIDE: u32 = 16;
/// Bytes of one `vec4<f32>`.
const VEC4_BYTES: u64 = 16;
/// Added to a point's `w` by the Laplacian pass that first moves it (`laplacian.wgsl`).
const MOVED: f32 = 1024.0;
/// Bytes of the uniform parameter block (8 × 4-byte words).
const PARAMS_BYTES: u64 = 32;

/// A GPU context for the organized-cloud filters, created once and reused: it holds the
/// device, the compiled pipelines and the buffers of the last cloud shape.
///
/// ```no_run
/// use mesh_smooth_gpu::{BilateralOptions, GpuSmoother, LaplacianOptions};
/// use opc_mesh::OrganizedPointCloud;
///
/// let mut gpu = GpuSmoother::new()?;
/// println!("running on {}", gpu.adapter_summary());
/// let points: Vec<[f64; 3]> = (0..64).map(|i| [(i % 8) as f64, (i / 8) as f64, 1.0]).collect();
/// let cloud = OrganizedPointCloud::new(8, 8, points).expect("8 × 8 points");
/// let smoothed = gpu.laplacian(&cloud, &LaplacianOptions::new())?;
/// let normals = gpu.bilateral(&smoothed, &BilateralOptions::new())?;
/// assert_eq!(normals.num_present(), 2 * 7 * 7);
/// # Ok::<(), mesh_smooth_gpu::SmoothError>(())
/// ```
pub struct GpuSmoother {
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter_info: Option<wgpu::AdapterInfo>,
    laplacian: wgpu::ComputePipeline,
    prepare: wgpu::ComputePipeline,
    filter: wgpu::ComputePipeline,
    params: wgpu::Buffer,
    buffers: Option<ShapeBuffers>,
}

impl std::fmt::Debug for GpuSmoother {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuSmoother")
            .field("adapter", &self.adapter_summary())
            .field(
                "buffers_for",
                &self.buffers.as_ref().map(|b| (b.rows, b.cols)),
            )
            .finish_non_exhaustive()
    }
}

/// Buffers and bind groups for one cloud shape.
struct ShapeBuffers {
    rows: usize,
    cols: usize,
    point_a: wgpu::Buffer,
    point_b: wgpu::Buffer,
    normal_a: wgpu::Buffer,
    normal_b: wgpu::Buffer,
    staging: wgpu::Buffer,
    laplacian_ab: wgpu::BindGroup,
    laplacian_ba: wgpu::BindGroup,
    /// Triangle normals and centroids of the points in `point_a` / `point_b`.
    prepare_a: wgpu::BindGroup,
    prepare_b: wgpu::BindGroup,
    filter_ab: wgpu::BindGroup,
    filter_ba: wgpu::BindGroup,
}

impl GpuSmoother {
    /// Finds a GPU adapter (high-performance preference; Vulkan, Metal or DX12 first, then
    /// any backend including GL; `WGPU_BACKEND` and the other wgpu environment variables
    /// are honoured), opens a device and compiles the shaders. Blocks (pollster) until done.
    ///
    /// # Errors
    /// [`SmoothError::NoAdapter`] when no adapter exists (no GPU and no software driver
    /// such as Mesa's lavapipe), [`SmoothError::RequestDevice`] when the adapter refuses.
    pub fn new() -> Result<Self, SmoothError> {
        pollster::block_on(Self::new_async())
    }

    /// The async form of [`Self::new`].
    ///
    /// # Errors
    /// As [`Self::new`].
    pub async fn new_async() -> Result<Self, SmoothError> {
        let adapter = match request_adapter(wgpu::Backends::PRIMARY).await {
            Ok(adapter) => adapter,
            Err(_) => request_adapter(wgpu::Backends::all()).await.map_err(|e| {
                SmoothError::NoAdapter {
                    reason: e.to_string(),
                }
            })?,
        };
        let info = adapter.get_info();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("mesh-smooth-gpu"),
                required_limits: adapter.limits(),
                ..Default::default()
            })
            .await
            .map_err(|e| SmoothError::RequestDevice {
                reason: e.to_string(),
            })?;
        let mut smoother = Self::from_device(&device, &queue);
        smoother.adapter_info = Some(info);
        Ok(smoother)
    }

    /// Builds the smoother on a device and queue the caller already has (the handles are
    /// cloned; wgpu handles are reference counted). Compiles the shaders.
    pub fn from_device(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let laplacian_module = device.create_shader_module(wgpu::include_wgsl!("laplacian.wgsl"));
        let bilateral_module = device.create_shader_module(wgpu::include_wgsl!("bilateral.wgsl"));
        let pipeline = |module: &wgpu::ShaderModule, entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mesh-smooth-gpu params"),
            size: PARAMS_BYTES,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            laplacian: pipeline(&laplacian_module, "laplacian"),
            prepare: pipeline(&bilateral_module, "prepare_triangles"),
            filter: pipeline(&bilateral_module, "filter_normals"),
            device: device.clone(),
            queue: queue.clone(),
            adapter_info: None,
            params,
            buffers: None,
        }
    }

    /// The adapter found by [`Self::new`] (`None` after [`Self::from_device`]).
    pub fn adapter_info(&self) -> Option<&wgpu::AdapterInfo> {
        self.adapter_info.as_ref()
    }

    /// One line naming the adapter, its type, backend and driver.
    pub fn adapter_summary(&self) -> String {
        match &self.adapter_info {
            Some(info) => format!(
                "{} ({:?}, {:?}, driver {} {})",
                info.name, info.device_type, info.backend, info.driver, info.driver_info
            ),
            None => "a caller-provided device".to_owned(),
        }
    }

    /// The Laplacian filter of [`crate::laplacian_filter`] on this GPU.
    ///
    /// # Errors
    /// Invalid options, a cloud too large for the device, or a GPU failure.
    pub fn laplacian(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &LaplacianOptions,
    ) -> Result<OrganizedPointCloud, SmoothError> {
        options.validate()?;
        self.run_laplacian(cloud, options, None)
    }

    /// The Laplacian filter with a pass count per pixel, as
    /// [`crate::CpuSmoother::laplacian_in_place_per_pixel`] (into a new cloud): pixel `i`
    /// moves in the first `passes[i]` passes only and keeps its place afterwards, still
    /// weighing in its neighbours' means; `options.iterations` is ignored.
    ///
    /// # Errors
    /// Invalid options, `passes` not one entry per point, a cloud too large for the
    /// device, or a GPU failure.
    pub fn laplacian_per_pixel(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &LaplacianOptions,
        passes: &[u8],
    ) -> Result<OrganizedPointCloud, SmoothError> {
        options.validate()?;
        crate::options::check_passes(passes, cloud)?;
        self.run_laplacian(cloud, options, Some(passes))
    }

    /// Uploads `cloud` with each valid point's pass count (`passes`, else
    /// `options.iterations`) in its `w`, runs the largest count of passes and reads back
    /// the points that moved. Options and `passes` are validated.
    fn run_laplacian(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &LaplacianOptions,
        passes: Option<&[u8]>,
    ) -> Result<OrganizedPointCloud, SmoothError> {
        let scopes = ErrorScopes::push(&self.device);
        let Some(iterations) = self.upload_laplacian(cloud, options, passes)? else {
            scopes.pop()?;
            return Ok(cloud.clone());
        };
        let (smoothed, _) = self.run_uploaded_laplacian(cloud, iterations)?;
        scopes.pop()?;
        Ok(smoothed)
    }

    /// Runs `iterations` Laplacian passes over the uploaded `cloud` and reads the result
    /// back; and whether it lies in `point_b` (else `point_a`) on the device.
    fn run_uploaded_laplacian(
        &self,
        cloud: &OrganizedPointCloud,
        iterations: u32,
    ) -> Result<(OrganizedPointCloud, bool), SmoothError> {
        let buffers = self.shape_buffers()?;
        let mut encoder = self.encoder("laplacian");
        let in_b = self.encode_laplacian(&mut encoder, buffers, iterations);
        let result = if in_b {
            &buffers.point_b
        } else {
            &buffers.point_a
        };
        let count = cloud.points().len();
        let data = self.read_back(encoder, result, &buffers.staging, count)?;
        Ok((moved(cloud, &data), in_b))
    }

    /// The bilateral normal filter of [`crate::bilateral_filter`] on this GPU, normals and
    /// centroids computed on the device too.
    ///
    /// # Errors
    /// Invalid options, a cloud too large for the device, or a GPU failure.
    pub fn bilateral(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &BilateralOptions,
    ) -> Result<SlotNormals, SmoothError> {
        options.validate()?;
        let (rows, cols) = (cloud.rows(), cloud.cols());
        let scopes = ErrorScopes::push(&self.device);
        self.ensure_buffers(rows, cols)?;
        let buffers = self.shape_buffers()?;
        self.queue.write_buffer(
            &buffers.point_a,
            0,
            bytemuck::cast_slice(&upload(cloud, |_| 1.0)),
        );
        let mut encoder = self.encoder("bilateral");
        let result = self.encode_bilateral(&mut encoder, buffers, options, false);
        let data = self.read_back(encoder, result, &buffers.staging, num_slots(rows, cols))?;
        scopes.pop()?;
        Ok(slot_normals(rows, cols, &data))
    }

    /// The Laplacian filter (with `passes` per pixel, else `laplacian.iterations`), then
    /// the bilateral filter of the smoothed cloud, which stays on the device: one upload,
    /// and the bilateral passes run on the GPU while `between` works on the smoothed cloud
    /// on the CPU (the pipeline meshes it there). The same numbers as
    /// [`Self::laplacian`] (or [`Self::laplacian_per_pixel`]) followed by
    /// [`Self::bilateral`] of its result.
    ///
    /// ```no_run
    /// use mesh_smooth_gpu::{BilateralOptions, GpuSmoother, LaplacianOptions};
    /// use opc_mesh::OrganizedPointCloud;
    ///
    /// let mut gpu = GpuSmoother::new()?;
    /// let points: Vec<[f64; 3]> = (0..64).map(|i| [(i % 8) as f64, (i / 8) as f64, 1.0]).collect();
    /// let cloud = OrganizedPointCloud::new(8, 8, points).expect("8 × 8 points");
    /// let (smoothed, valid, normals) = gpu.laplacian_then_bilateral(
    ///     &cloud,
    ///     &LaplacianOptions::new(),
    ///     None,
    ///     &BilateralOptions::new(),
    ///     |smoothed| smoothed.num_valid(),
    /// )?;
    /// assert_eq!((smoothed.num_valid(), valid, normals.num_present()), (64, 64, 2 * 7 * 7));
    /// # Ok::<(), mesh_smooth_gpu::SmoothError>(())
    /// ```
    ///
    /// # Errors
    /// Invalid options, `passes` not one entry per point, a cloud too large for the
    /// device, or a GPU failure.
    pub fn laplacian_then_bilateral<R>(
        &mut self,
        cloud: &OrganizedPointCloud,
        laplacian: &LaplacianOptions,
        passes: Option<&[u8]>,
        bilateral: &BilateralOptions,
        between: impl FnOnce(&OrganizedPointCloud) -> R,
    ) -> Result<(OrganizedPointCloud, R, SlotNormals), SmoothError> {
        laplacian.validate()?;
        bilateral.validate()?;
        if let Some(passes) = passes {
            crate::options::check_passes(passes, cloud)?;
        }
        let (rows, cols) = (cloud.rows(), cloud.cols());
        let scopes = ErrorScopes::push(&self.device);
        let Some(iterations) = self.upload_laplacian(cloud, laplacian, passes)? else {
            scopes.pop()?;
            let between = between(cloud);
            let normals = self.bilateral(cloud, bilateral)?;
            return Ok((cloud.clone(), between, normals));
        };
        let (smoothed, in_b) = self.run_uploaded_laplacian(cloud, iterations)?;
        let buffers = self.shape_buffers()?;
        let mut encoder = self.encoder("bilateral");
        let result = self.encode_bilateral(&mut encoder, buffers, bilateral, in_b);
        let slots = num_slots(rows, cols);
        self.submit_copy(encoder, result, &buffers.staging, slots);
        let between = between(&smoothed);
        let data = self.map_read(&buffers.staging, slots)?;
        scopes.pop()?;
        Ok((smoothed, between, slot_normals(rows, cols, &data)))
    }

    /// Allocates the buffers for `cloud`'s shape, uploads it with each valid point's pass
    /// count (`passes`, else `options.iterations`) plus 1 in its `w`, and writes the
    /// Laplacian's parameters; the passes to run (the largest count), or `None` when
    /// there is nothing to filter.
    fn upload_laplacian(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &LaplacianOptions,
        passes: Option<&[u8]>,
    ) -> Result<Option<u32>, SmoothError> {
        let (rows, cols) = (cloud.rows(), cloud.cols());
        let half = options.kernel / 2;
        let iterations = passes.map_or(options.iterations, |p| {
            u32::from(p.iter().copied().max().unwrap_or(0))
        });
        if iterations == 0 || rows <= 2 * half as usize || cols <= 2 * half as usize {
            return Ok(None);
        }
        self.ensure_buffers(rows, cols)?;
        let points = upload(cloud, |i| {
            passes.map_or(iterations as f32, |p| f32::from(p[i])) + 1.0
        });
        let buffers = self.shape_buffers()?;
        self.queue
            .write_buffer(&buffers.point_a, 0, bytemuck::cast_slice(&points));
        self.write_params(rows, cols, half, options.lambda, options.epsilon);
        Ok(Some(iterations))
    }

    /// Encodes `iterations` Laplacian passes over the uploaded cloud; whether the result
    /// lies in `point_b` (else `point_a`).
    fn encode_laplacian(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        buffers: &ShapeBuffers,
        iterations: u32,
    ) -> bool {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("laplacian"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.laplacian);
        for it in 0..iterations {
            let group = if it % 2 == 0 {
                &buffers.laplacian_ab
            } else {
                &buffers.laplacian_ba
            };
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(groups(buffers.cols), groups(buffers.rows), 1);
        }
        iterations % 2 == 1
    }

    /// Writes the bilateral filter's parameters and encodes its passes over the points in
    /// `point_b` (`points_in_b`) or `point_a`; the buffer that holds the normals.
    fn encode_bilateral<'b>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        buffers: &'b ShapeBuffers,
        options: &BilateralOptions,
        points_in_b: bool,
    ) -> &'b wgpu::Buffer {
        let (rows, cols) = (buffers.rows, buffers.cols);
        let (inv_var_length, inv_var_angle) = options.inverse_variances();
        self.write_params(
            rows,
            cols,
            options.kernel / 2,
            inv_var_length,
            inv_var_angle,
        );
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bilateral"),
            timestamp_writes: None,
        });
        let (x, y) = (groups(cols - 1), groups(rows - 1));
        pass.set_pipeline(&self.prepare);
        let prepare = if points_in_b {
            &buffers.prepare_b
        } else {
            &buffers.prepare_a
        };
        pass.set_bind_group(0, prepare, &[]);
        pass.dispatch_workgroups(x, y, 1);
        pass.set_pipeline(&self.filter);
        for it in 0..options.iterations {
            let group = if it % 2 == 0 {
                &buffers.filter_ab
            } else {
                &buffers.filter_ba
            };
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
        if options.iterations.is_multiple_of(2) {
            &buffers.normal_a
        } else {
            &buffers.normal_b
        }
    }

    fn encoder(&self, label: &str) -> wgpu::CommandEncoder {
        self.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) })
    }

    /// The buffers [`Self::ensure_buffers`] allocated.
    fn shape_buffers(&self) -> Result<&ShapeBuffers, SmoothError> {
        self.buffers.as_ref().ok_or_else(missing_buffers)
    }

    fn write_params(&self, rows: usize, cols: usize, half: u32, a: f32, b: f32) {
        // Shapes were checked against the dispatch limits in `ensure_buffers`.
        let words: [u32; 8] = [
            rows as u32,
            cols as u32,
            half,
            0,
            a.to_bits(),
            b.to_bits(),
            0,
            0,
        ];
        self.queue
            .write_buffer(&self.params, 0, bytemuck::cast_slice(&words));
    }

    /// Allocates buffers and bind groups for a `rows × cols` cloud unless the last call
    /// already did.
    fn ensure_buffers(&mut self, rows: usize, cols: usize) -> Result<(), SmoothError> {
        if self
            .buffers
            .as_ref()
            .is_some_and(|b| b.rows == rows && b.cols == cols)
        {
            return Ok(());
        }
        self.buffers = None;
        let limits = self.device.limits();
        let max_groups = limits.max_compute_workgroups_per_dimension as usize;
        let max_side = max_groups * WORKGROUP_SIDE as usize;
        if rows > max_side || cols > max_side {
            return Err(SmoothError::GridTooLargeForGpu {
                rows,
                cols,
                max_side,
            });
        }
        let point_bytes = rows as u64 * cols as u64 * VEC4_BYTES;
        let slot_bytes = num_slots(rows, cols) as u64 * VEC4_BYTES;
        let needed = point_bytes.max(slot_bytes);
        let limit = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        if needed > limit {
            return Err(SmoothError::CloudTooLargeForGpu { needed, limit });
        }
        let storage = |label: &str, size: u64| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let point_a = storage("points a", point_bytes);
        let point_b = storage("points b", point_bytes);
        let normal_a = storage("normals a", slot_bytes);
        let normal_b = storage("normals b", slot_bytes);
        let centroids = storage("centroids", slot_bytes);
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read-back"),
            size: needed,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = |pipeline: &wgpu::ComputePipeline, entries: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<wgpu::BindGroupEntry<'_>> = entries
                .iter()
                .map(|&(binding, buffer)| wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                })
                .collect();
            self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        let params = &self.params;
        let laplacian_ab = bind(
            &self.laplacian,
            &[(0, params), (1, &point_a), (2, &point_b)],
        );
        let laplacian_ba = bind(
            &self.laplacian,
            &[(0, params), (1, &point_b), (2, &point_a)],
        );
        let prepare = |points: &wgpu::Buffer| {
            bind(
                &self.prepare,
                &[(0, params), (1, points), (2, &centroids), (3, &normal_a)],
            )
        };
        let (prepare_a, prepare_b) = (prepare(&point_a), prepare(&point_b));
        let filter_ab = bind(
            &self.filter,
            &[(0, params), (3, &normal_b), (4, &centroids), (5, &normal_a)],
        );
        let filter_ba = bind(
            &self.filter,
            &[(0, params), (3, &normal_a), (4, &centroids), (5, &normal_b)],
        );
        self.buffers = Some(ShapeBuffers {
            rows,
            cols,
            point_a,
            point_b,
            normal_a,
            normal_b,
            staging,
            laplacian_ab,
            laplacian_ba,
            prepare_a,
            prepare_b,
            filter_ab,
            filter_ba,
        });
        Ok(())
    }

    /// Submits `encoder` plus a copy of the first `count` vec4s of `source` into
    /// `staging`, waits, and returns them.
    fn read_back(
        &self,
        encoder: wgpu::CommandEncoder,
        source: &wgpu::Buffer,
        staging: &wgpu::Buffer,
        count: usize,
    ) -> Result<Vec<[f32; 4]>, SmoothError> {
        self.submit_copy(encoder, source, staging, count);
        self.map_read(staging, count)
    }

    /// Submits `encoder` plus a copy of the first `count` vec4s of `source` into
    /// `staging`, without waiting.
    fn submit_copy(
        &self,
        mut encoder: wgpu::CommandEncoder,
        source: &wgpu::Buffer,
        staging: &wgpu::Buffer,
        count: usize,
    ) {
        encoder.copy_buffer_to_buffer(source, 0, staging, 0, count as u64 * VEC4_BYTES);
        self.queue.submit(Some(encoder.finish()));
    }

    /// Waits for the submitted work and returns the first `count` vec4s of `staging`.
    fn map_read(&self, staging: &wgpu::Buffer, count: usize) -> Result<Vec<[f32; 4]>, SmoothError> {
        let slice = staging.slice(..count as u64 * VEC4_BYTES);
        let (sender, receiver) = mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            // The receiver waits below; a send can only fail if it is gone.
            let _ = sender.send(result);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(gpu_error)?;
        receiver.recv().map_err(gpu_error)?.map_err(gpu_error)?;
        let data = {
            let view = slice.get_mapped_range().map_err(gpu_error)?;
            bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(&view)
        };
        staging.unmap();
        Ok(data)
    }
}

/// Validation and out-of-memory error scopes around one filter call.
struct ErrorScopes {
    validation: wgpu::ErrorScopeGuard,
    out_of_memory: wgpu::ErrorScopeGuard,
}

impl ErrorScopes {
    fn push(device: &wgpu::Device) -> Self {
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let out_of_memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        Self {
            validation,
            out_of_memory,
        }
    }

    fn pop(self) -> Result<(), SmoothError> {
        let Self {
            validation,
            out_of_memory,
        } = self;
        let oom = pollster::block_on(out_of_memory.pop());
        let invalid = pollster::block_on(validation.pop());
        match oom.or(invalid) {
            Some(e) => Err(gpu_error(e)),
            None => Ok(()),
        }
    }
}

/// Adapter requests made by [`GpuSmoother::new`] in this process; see
/// [`crate::adapter_requests`].
static ADAPTER_REQUESTS: AtomicU64 = AtomicU64::new(0);

/// How many times this process has asked wgpu for an adapter; see
/// [`crate::adapter_requests`].
pub fn adapter_requests() -> u64 {
    ADAPTER_REQUESTS.load(Ordering::Relaxed)
}

/// An adapter from the given backends (overridable by `WGPU_BACKEND`).
async fn request_adapter(
    backends: wgpu::Backends,
) -> Result<wgpu::Adapter, wgpu::RequestAdapterError> {
    ADAPTER_REQUESTS.fetch_add(1, Ordering::Relaxed);
    let instance = wgpu::Instance::new(
        wgpu::InstanceDescriptor {
            backends,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        }
        .with_env(),
    );
    instance
        .request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        })
        .await
}

/// Workgroups covering `n` invocations along one axis.
fn groups(n: usize) -> u32 {
    n.div_ceil(WORKGROUP_SIDE as usize) as u32
}

/// The cloud as vec4s: xyz and w = 1 for valid points, all zero for invalid ones.
/// `cloud` with the points a Laplacian pass moved (`w ≥ MOVED` in `data`) replaced.
fn moved(cloud: &OrganizedPointCloud, data: &[[f32; 4]]) -> OrganizedPointCloud {
    let mut out = cloud.clone();
    for (p, v) in out.points_mut().iter_mut().zip(data) {
        if v[3] >= MOVED {
            *p = [f64::from(v[0]), f64::from(v[1]), f64::from(v[2])];
        }
    }
    out
}

/// The bilateral filter's read-back normals (`w > 0` where the triangle exists).
fn slot_normals(rows: usize, cols: usize, data: &[[f32; 4]]) -> SlotNormals {
    let normals = data
        .iter()
        .map(|v| {
            if v[3] > 0.0 {
                [v[0], v[1], v[2]]
            } else {
                [f32::NAN; 3]
            }
        })
        .collect();
    SlotNormals::new(rows, cols, normals)
}

/// The cloud as `vec4<f32>`: a valid point `i` with `w = valid_w(i)` (≥ 1), an invalid
/// one as zeros.
fn upload(cloud: &OrganizedPointCloud, valid_w: impl Fn(usize) -> f32) -> Vec<[f32; 4]> {
    cloud
        .points()
        .iter()
        .enumerate()
        .map(|(i, p)| {
            if opc_mesh::is_valid(p) {
                [p[0] as f32, p[1] as f32, p[2] as f32, valid_w(i)]
            } else {
                [0.0; 4]
            }
        })
        .collect()
}

fn gpu_error(e: impl std::fmt::Display) -> SmoothError {
    SmoothError::Gpu {
        reason: e.to_string(),
    }
}

fn missing_buffers() -> SmoothError {
    SmoothError::Gpu {
        reason: "buffers were not allocated".to_owned(),
    }
}

impl crate::Smoother for GpuSmoother {
    fn laplacian(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &LaplacianOptions,
    ) -> Result<OrganizedPointCloud, SmoothError> {
        GpuSmoother::laplacian(self, cloud, options)
    }

    fn bilateral(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &BilateralOptions,
    ) -> Result<SlotNormals, SmoothError> {
        GpuSmoother::bilateral(self, cloud, options)
    }
}
