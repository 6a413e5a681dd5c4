//! What one [`Polylidar`](crate::Polylidar) keeps between runs: the parts of the 3D
//! pipeline that cost more to build than to use (the FastGA accumulator, the smoothers'
//! and the segmenter's buffers, the GPU smoother's adapter, device, pipelines and
//! buffers).

use std::sync::{Mutex, MutexGuard, PoisonError};

use fastga::FastGa;
use halfedge_mesh::HalfEdgeMesh;
use mesh_smooth_gpu::{
    BilateralOptions, CpuSmoother, GpuSmoother, LaplacianOptions, SmoothError, Smoother,
};
use opc_mesh::{OpcError, OpcMesh, OrganizedPointCloud, OrganizedPointCloudView, TriangleMap};
use planeseg::Segmenter;

use crate::SmoothingBackend;

/// Detectors and buffers reused across runs. Every use starts from a clean state (the
/// accumulator is cleared, buffers are overwritten), so results do not depend on what ran
/// before.
///
/// A run takes what it needs out of the shared slot and puts it back when done; the lock
/// is held only for those moves, never while the run computes. A run's thread is a rayon
/// worker, which while waiting inside its run may start another run: had the first run
/// held the lock, the second would wait for it on the same thread forever. Runs at the
/// same time (a stream's frames in flight, callers on several threads) each take their
/// own: a run that finds none left makes its own, and up to [`KEPT`] of each kind are
/// kept for the runs to come.
#[derive(Debug, Default)]
pub(crate) struct Reusable {
    /// FastGA detectors, built on the first 3D run.
    pub fastga: Kept<FastGa>,
    /// Planar segmentation's per-triangle buffers.
    pub segmenter: Kept<Segmenter>,
    /// The organized pipeline's smoothers and frame buffers.
    pub organized: Kept<Organized>,
}

/// Parts of one kind are kept for as many runs at once as this, the most frames a stream
/// runs at once ([`crate::stream::StreamOptions::in_flight`]).
pub(crate) const KEPT: usize = 4;

/// Parts of one kind waiting for the next runs, the last put back first out.
#[derive(Debug)]
pub(crate) struct Kept<T>(Vec<T>);

impl<T> Default for Kept<T> {
    fn default() -> Self {
        Self(Vec::new())
    }
}

impl<T> Kept<T> {
    /// A kept part, if any is left.
    pub fn take(&mut self) -> Option<T> {
        self.0.pop()
    }

    /// Keeps `part` for a later run; returns it when [`KEPT`] are kept already, for the
    /// caller to drop after releasing the lock (a GPU smoother's teardown can take a
    /// while).
    #[must_use]
    pub fn put(&mut self, part: T) -> Option<T> {
        if self.0.len() < KEPT {
            self.0.push(part);
            None
        } else {
            Some(part)
        }
    }
}

impl Kept<Organized> {
    /// Keeps the arrays of `mesh` for the next organized frame: with kept buffers that
    /// have none, else beside them; returns it when [`KEPT`] have one already.
    #[must_use]
    pub fn recycle(&mut self, mesh: HalfEdgeMesh) -> Option<HalfEdgeMesh> {
        if let Some(organized) = self.0.iter_mut().rev().find(|o| o.recycled.is_none()) {
            organized.recycled = Some(mesh);
            return None;
        }
        let organized = Organized {
            recycled: Some(mesh),
            ..Organized::default()
        };
        self.put(organized).and_then(|o| o.recycled)
    }
}

/// The shared slot; a run that panicked while holding it left nothing that the next
/// run's clean start does not overwrite, so a poisoned lock is taken over.
pub(crate) fn lock(slot: &Mutex<Reusable>) -> MutexGuard<'_, Reusable> {
    slot.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The organized pipeline's part of [`Reusable`], taken out of the shared slot for a
/// run by [`Organized::take_from`].
#[derive(Debug, Default)]
pub(crate) struct Organized {
    /// CPU smoothers: one thread, rayon.
    smoothers: [Option<CpuSmoother>; 2],
    /// The GPU smoother (adapter, device, compiled pipelines, buffers of the last frame
    /// shape), created on the first GPU run and kept: a stream of frames asks for one
    /// adapter.
    gpu: Option<GpuSmoother>,
    /// The arrays of a mesh handed back by [`crate::Polylidar::recycle`], to mesh the next
    /// organized frame into.
    pub recycled: Option<HalfEdgeMesh>,
    /// The last organized frame's triangle map, storage for the next one's.
    pub triangle_map: Option<TriangleMap>,
}

/// [`Organized`] taken out of a shared slot, put back when dropped (also when the run
/// fails or unwinds).
pub(crate) struct Taken<'a> {
    slot: &'a Mutex<Reusable>,
    state: Organized,
}

impl Organized {
    /// Takes an organized part out of `slot` for one run (a fresh one when none is kept).
    pub fn take_from(slot: &Mutex<Reusable>) -> Taken<'_> {
        let state = lock(slot).organized.take().unwrap_or_default();
        Taken { slot, state }
    }

    /// Storage to mesh the next organized frame into: the recycled mesh's arrays and the
    /// last triangle map, or empty arrays.
    pub fn mesh_storage(&mut self) -> OpcMesh {
        OpcMesh {
            mesh: self.recycled.take().unwrap_or_default(),
            triangle_map: self.triangle_map.take().unwrap_or_default(),
        }
    }

    /// The recycled mesh's vertex buffer (empty without one), for the next frame's points
    /// (decimated, or smoothed from the caller's cloud), which become its mesh's vertices:
    /// the other arrays stay for meshing.
    pub fn take_recycled_vertices(&mut self) -> Vec<[f64; 3]> {
        let Some(mesh) = self.recycled.take() else {
            return Vec::new();
        };
        let (vertices, triangles, halfedges, normals) = mesh.into_parts();
        self.recycled = Some(HalfEdgeMesh::from_parts_trusted(
            Vec::new(),
            triangles,
            halfedges,
            normals,
        ));
        vertices
    }

    /// A copy of `view` in the recycled mesh's vertex buffer ([`Self::take_recycled_vertices`]),
    /// so that a stream of frames copies each into the memory of the one before instead of
    /// allocating (and the kernel zeroing) a frame's worth of new pages.
    pub fn copy_of(
        &mut self,
        view: OrganizedPointCloudView<'_>,
    ) -> Result<OrganizedPointCloud, OpcError> {
        let mut points = self.take_recycled_vertices();
        points.clear();
        points.extend_from_slice(view.points());
        OrganizedPointCloud::new(view.rows(), view.cols(), points)
    }

    /// The kept smoother of `backend`, created on its first use.
    fn smoother(&mut self, backend: SmoothingBackend) -> Result<&mut dyn Smoother, SmoothError> {
        Ok(match backend {
            SmoothingBackend::Gpu => self.gpu()?,
            cpu => self.cpu(cpu),
        })
    }

    /// The kept CPU smoother: one thread for [`SmoothingBackend::Cpu`], the pool
    /// otherwise.
    pub fn cpu(&mut self, backend: SmoothingBackend) -> &mut CpuSmoother {
        let parallel = backend != SmoothingBackend::Cpu;
        self.smoothers[usize::from(parallel)].get_or_insert_with(|| match parallel {
            true => CpuSmoother::new(),
            false => CpuSmoother::serial(),
        })
    }

    /// The kept GPU smoother, created on its first use.
    pub fn gpu(&mut self) -> Result<&mut GpuSmoother, SmoothError> {
        match &mut self.gpu {
            Some(gpu) => Ok(gpu),
            slot => Ok(slot.insert(GpuSmoother::new()?)),
        }
    }

    /// The Laplacian filter of `cloud` on the kept smoother of `backend`.
    pub fn laplacian(
        &mut self,
        backend: SmoothingBackend,
        cloud: &OrganizedPointCloud,
        options: &LaplacianOptions,
    ) -> Result<OrganizedPointCloud, SmoothError> {
        self.smoother(backend)?.laplacian(cloud, options)
    }

    /// The Laplacian filter of `cloud`, overwriting it, on the kept smoother of `backend`
    /// (the GPU filters into a new cloud that replaces it).
    pub fn laplacian_in_place(
        &mut self,
        backend: SmoothingBackend,
        cloud: &mut OrganizedPointCloud,
        options: &LaplacianOptions,
    ) -> Result<(), SmoothError> {
        match backend {
            SmoothingBackend::Gpu => {
                *cloud = self.gpu()?.laplacian(cloud, options)?;
                Ok(())
            }
            cpu => self.cpu(cpu).laplacian_in_place(cloud, options),
        }
    }

    /// The Laplacian filter of `cloud` with a pass count per pixel, overwriting it, on the
    /// kept smoother of `backend` (the GPU filters into a new cloud that replaces it).
    pub fn laplacian_per_pixel(
        &mut self,
        backend: SmoothingBackend,
        cloud: &mut OrganizedPointCloud,
        options: &LaplacianOptions,
        passes: &[u8],
    ) -> Result<(), SmoothError> {
        match backend {
            SmoothingBackend::Gpu => {
                *cloud = self.gpu()?.laplacian_per_pixel(cloud, options, passes)?;
                Ok(())
            }
            cpu => self
                .cpu(cpu)
                .laplacian_in_place_per_pixel(cloud, options, passes),
        }
    }

    /// The bilateral normal filter of `cloud`'s implicit mesh, written into `opc`'s
    /// triangle normals, on the kept smoother of `backend`.
    pub fn bilateral(
        &mut self,
        backend: SmoothingBackend,
        cloud: &OrganizedPointCloud,
        options: &BilateralOptions,
        opc: &mut OpcMesh,
    ) -> Result<(), SmoothError> {
        match backend {
            SmoothingBackend::Gpu => self
                .gpu()?
                .bilateral(cloud, options)?
                .apply_to_opc_mesh(opc),
            cpu => self.cpu(cpu).bilateral_into_mesh(cloud, options, opc),
        }
    }
}

impl std::ops::Deref for Taken<'_> {
    type Target = Organized;

    fn deref(&self) -> &Organized {
        &self.state
    }
}

impl std::ops::DerefMut for Taken<'_> {
    fn deref_mut(&mut self) -> &mut Organized {
        &mut self.state
    }
}

impl Drop for Taken<'_> {
    fn drop(&mut self) {
        let state = std::mem::take(&mut self.state);
        let left = lock(self.slot).organized.put(state);
        // Dropped after the lock is released.
        drop(left);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kept_parts_are_capped_and_recycled_meshes_go_where_none_is() {
        let mut kept = Kept::<Organized>::default();
        for _ in 0..KEPT {
            assert!(kept.put(Organized::default()).is_none());
        }
        assert!(kept.put(Organized::default()).is_some());
        for _ in 0..KEPT {
            assert!(kept.recycle(HalfEdgeMesh::default()).is_none());
        }
        assert!(kept.0.iter().all(|o| o.recycled.is_some()));
        assert!(kept.recycle(HalfEdgeMesh::default()).is_some());
        // Two runs at once take two parts, each with its recycled mesh, and put them back.
        let (a, b) = (kept.take().unwrap(), kept.take().unwrap());
        assert!(a.recycled.is_some() && b.recycled.is_some());
        assert!(kept.put(a).is_none() && kept.put(b).is_none());
        let mut fresh = Kept::<Organized>::default();
        assert!(fresh.recycle(HalfEdgeMesh::default()).is_none());
        assert!(fresh.take().unwrap().recycled.is_some());
    }
}
