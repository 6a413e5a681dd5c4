//! The integration driver shared by the accumulators: input conversion, validity filter,
//! deterministic sampling, and sequential or rayon-parallel binning with results independent
//! of the thread count.

use rayon::prelude::*;

use crate::FastGaError;
use crate::icosahedron::dot;

/// Scale of the fixed-point per-cell normal sums: integer sums are exact and associative, so
/// they do not depend on the order (and thread count) in which normals are added.
pub(crate) const SUM_SCALE: f64 = (1u64 << 30) as f64;

/// Normals per parallel task.
const CHUNK: usize = 8192;

/// Normals searched together, so that the searches' memory latencies overlap.
pub(crate) const BATCH: usize = 32;

/// A 3D normal that the accumulators can integrate: implemented for `[f64; 3]` and `[f32; 3]`.
pub trait AsNormal: Sync {
    /// The normal in double precision.
    fn to_f64(&self) -> [f64; 3];
}

impl AsNormal for [f64; 3] {
    #[inline(always)]
    fn to_f64(&self) -> [f64; 3] {
        *self
    }
}

impl AsNormal for [f32; 3] {
    #[inline(always)]
    fn to_f64(&self) -> [f64; 3] {
        self.map(f64::from)
    }
}

/// Whether integration runs on the calling thread or on the current rayon thread pool.
///
/// Results are identical either way and for any number of threads: counts and the
/// fixed-point normal sums are integers. Run inside `ThreadPool::install` to choose the
/// thread count.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Parallelism {
    /// One thread: the caller's.
    Sequential,
    /// Chunks of the input on the current rayon pool (the global pool unless installed).
    #[default]
    Rayon,
}

/// What one call to `integrate` did with its input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct IntegrateStats {
    /// Normals binned into a cell.
    pub integrated: u64,
    /// Normals skipped because they are NaN, infinite or not of unit length.
    pub skipped_invalid: u64,
    /// Normals left out by `sample_fraction`.
    pub skipped_by_sampling: u64,
}

impl IntegrateStats {
    fn add(&mut self, other: &Self) {
        self.integrated += other.integrated;
        self.skipped_invalid += other.skipped_invalid;
        self.skipped_by_sampling += other.skipped_by_sampling;
    }
}

/// Deterministic selection of a fraction of the input by a hash of each normal's index: the
/// same normals are kept for any thread count, without the aliasing of a fixed stride on
/// structured (e.g. organized) inputs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sampler {
    /// Keep index `i` when `mix(i) < threshold`; `None` keeps everything.
    threshold: Option<u64>,
}

impl Sampler {
    pub(crate) fn new(fraction: f64) -> Result<Self, FastGaError> {
        if !(fraction > 0.0 && fraction <= 1.0) {
            return Err(FastGaError::InvalidSampleFraction(fraction));
        }
        let threshold = (fraction < 1.0).then(|| (fraction * 2f64.powi(64)) as u64);
        Ok(Self { threshold })
    }

    #[cfg(test)]
    fn keep(self, index: u64) -> bool {
        self.threshold.is_none_or(|t| mix(index) < t)
    }
}

/// The indices a [`Sampler`] keeps, hashed once and kept across calls: whether an index
/// is kept depends on the index alone, so an accumulator reused over a stream of frames
/// (whose normal counts differ a little from frame to frame) hashes each index once, not
/// once a frame, and reads the kept ones from this list. Hashing every index on every call
/// took a quarter of the FastGA stage of a 424 × 240 depth frame.
#[derive(Debug, Clone, Default)]
pub(crate) struct SampleCache {
    /// The threshold the indices were hashed against.
    threshold: u64,
    /// Every index below this has been hashed.
    hashed: usize,
    /// The kept indices below `hashed`, ascending.
    kept: Vec<usize>,
}

impl SampleCache {
    /// The indices below `len` that `sampler` keeps, ascending; `None` when it keeps all.
    /// Indices not hashed yet are hashed first, in parallel with [`Parallelism::Rayon`].
    pub(crate) fn kept(
        &mut self,
        sampler: Sampler,
        len: usize,
        parallelism: Parallelism,
    ) -> Option<&[usize]> {
        let threshold = sampler.threshold?;
        if threshold != self.threshold {
            *self = Self {
                threshold,
                ..Self::default()
            };
        }
        if len > self.hashed {
            let hash = |start: usize| {
                let end = (start + CHUNK).min(len);
                let mut offsets = [0u16; SAMPLE_BLOCK];
                let mut kept = Vec::new();
                for block in (start..end).step_by(SAMPLE_BLOCK) {
                    let count = kept_offsets(
                        threshold,
                        block as u64,
                        (end - block).min(SAMPLE_BLOCK),
                        &mut offsets,
                    );
                    kept.extend(offsets[..count].iter().map(|&o| block + usize::from(o)));
                }
                kept
            };
            let starts = self.hashed..len;
            let pieces: Vec<Vec<usize>> = match parallelism {
                Parallelism::Sequential => starts.step_by(CHUNK).map(hash).collect(),
                Parallelism::Rayon => starts.into_par_iter().step_by(CHUNK).map(hash).collect(),
            };
            self.kept.extend(pieces.into_iter().flatten());
            self.hashed = len;
        }
        Some(&self.kept[..self.kept.partition_point(|&i| i < len)])
    }
}

/// Indices per block of [`kept_offsets`].
const SAMPLE_BLOCK: usize = 256;

/// The offsets `o < len` (at most [`SAMPLE_BLOCK`]) of the indices `first + o` whose
/// [`mix`] lies below `threshold`, in order, into `kept`; returns their count. The hashes
/// of a whole block are computed first, vectorised where the CPU allows, and the offsets
/// then gathered branch-free: a kept index is as unpredictable as the hash.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx512dq", "x86_64+avx2"))]
fn kept_offsets(threshold: u64, first: u64, len: usize, kept: &mut [u16; SAMPLE_BLOCK]) -> usize {
    let mut keep = [0u16; SAMPLE_BLOCK];
    for (o, k) in keep.iter_mut().enumerate() {
        *k = u16::from(mix(first.wrapping_add(o as u64)) < threshold);
    }
    let mut count = 0;
    for (o, &k) in keep.iter().enumerate().take(len) {
        kept[count] = o as u16;
        count += usize::from(k);
    }
    count
}

/// SplitMix64 finaliser of `index` offset by a fixed odd constant.
#[inline(always)]
fn mix(index: u64) -> u64 {
    let mut z = index.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Per-cell counts and fixed-point sums of the normals binned there.
#[derive(Debug, Clone)]
pub(crate) struct Bins {
    pub(crate) counts: Vec<u64>,
    pub(crate) sums: Vec<[i64; 3]>,
    /// Empty bins for the parallel parts of [`Driver::run`] after the first, kept across
    /// calls. Fresh bins per rayon task each cost an allocation, a clear and a pass to add
    /// them up: at level 5 (20,480 cells, 640 KiB a set), about ten of them took a
    /// quarter of the FastGA stage of a 640 × 480 frame.
    parts: Vec<Bins>,
}

impl Bins {
    pub(crate) fn new(cells: usize) -> Self {
        Self {
            counts: vec![0; cells],
            sums: vec![[0; 3]; cells],
            parts: Vec::new(),
        }
    }

    pub(crate) fn clear(&mut self) {
        self.counts.fill(0);
        self.sums.fill([0; 3]);
    }

    /// Adds `other`'s counts and sums to these and empties `other`, in one pass.
    fn take(&mut self, other: &mut Self) {
        for (a, b) in self.counts.iter_mut().zip(&mut other.counts) {
            *a += std::mem::take(b);
        }
        for (a, b) in self.sums.iter_mut().zip(&mut other.sums) {
            for k in 0..3 {
                a[k] = a[k].wrapping_add(std::mem::take(&mut b[k]));
            }
        }
    }

    #[inline(always)]
    fn add(&mut self, cell: usize, p: [f64; 3]) {
        self.counts[cell] += 1;
        let sum = &mut self.sums[cell];
        for k in 0..3 {
            sum[k] = sum[k].wrapping_add(fixed_point(p[k]));
        }
    }
}

/// `x · 2³⁰` rounded to the nearest integer, for |x| ≤ 2 (unit normals within the
/// tolerance): added to 1.5 · 2⁵², the sum's low mantissa bits are that integer, which is
/// cheaper than a saturating float-to-integer conversion.
#[inline(always)]
fn fixed_point(x: f64) -> i64 {
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    (x * SUM_SCALE + SHIFT).to_bits() as i64 - SHIFT.to_bits() as i64
}

/// Settings of one integration.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Driver<'a> {
    /// The indices of the normals to bin, ascending ([`SampleCache::kept`]); `None`: all.
    pub(crate) kept: Option<&'a [usize]>,
    pub(crate) unit_tolerance: f64,
    pub(crate) parallelism: Parallelism,
}

impl Driver<'_> {
    /// Bins `normals` into `bins`; `find` writes the cell index of each normal of a batch of
    /// at most [`BATCH`] into the matching place of its second argument.
    pub(crate) fn run<N, F>(&self, normals: &[N], bins: &mut Bins, find: F) -> IntegrateStats
    where
        N: AsNormal,
        F: Fn(&[[f64; 3]], &mut [u32]) + Sync,
    {
        match self.parallelism {
            Parallelism::Sequential => self.chunk(normals, 0, bins, &find),
            Parallelism::Rayon => {
                let cells = bins.counts.len();
                // One part per worker, of at least a chunk, and no more parts than the
                // input has normals per cell: the first part bins into `bins`, the
                // others into kept bins that are then added in and emptied.
                let parts = rayon::current_num_threads()
                    .min(normals.len().div_ceil(CHUNK))
                    .min(normals.len() / cells.max(1))
                    .max(1);
                let len = normals.len().div_ceil(parts).max(1);
                let mut spare = std::mem::take(&mut bins.parts);
                spare.resize_with(parts - 1, || Bins::new(cells));
                let targets: Vec<&mut Bins> = std::iter::once(&mut *bins)
                    .chain(spare.iter_mut())
                    .collect();
                let stats = normals
                    .par_chunks(len)
                    .zip(targets)
                    .enumerate()
                    .map(|(k, (part, target))| self.chunk(part, k * len, target, &find))
                    .reduce(IntegrateStats::default, |mut a, b| {
                        a.add(&b);
                        a
                    });
                for part in &mut spare {
                    bins.take(part);
                }
                bins.parts = spare;
                stats
            }
        }
    }

    #[inline(always)]
    fn chunk<N, F>(&self, chunk: &[N], first: usize, bins: &mut Bins, find: &F) -> IntegrateStats
    where
        N: AsNormal,
        F: Fn(&[[f64; 3]], &mut [u32]),
    {
        let mut stats = IntegrateStats::default();
        let mut batch = [[0.0; 3]; BATCH];
        let mut cells = [0u32; BATCH];
        let mut len = 0;
        let mut flush = |batch: &[[f64; 3]], cells: &mut [u32]| {
            find(batch, cells);
            for (&p, &c) in batch.iter().zip(cells.iter()) {
                bins.add(c as usize, p);
            }
        };
        let mut take = |n: &N| {
            let p = n.to_f64();
            // NaN and infinities fail this comparison too.
            let unit = (dot(p, p) - 1.0).abs() <= self.unit_tolerance;
            if !unit {
                stats.skipped_invalid += 1;
                return;
            }
            batch[len] = p;
            len += 1;
            if len == BATCH {
                flush(&batch, &mut cells);
                len = 0;
            }
        };
        let sampled = match self.kept {
            None => {
                chunk.iter().for_each(&mut take);
                chunk.len()
            }
            Some(all) => {
                let from = all.partition_point(|&i| i < first);
                let to = all.partition_point(|&i| i < first + chunk.len());
                for &i in &all[from..to] {
                    take(&chunk[i - first]);
                }
                to - from
            }
        };
        flush(&batch[..len], &mut cells[..len]);
        stats.skipped_by_sampling = (chunk.len() - sampled) as u64;
        stats.integrated = sampled as u64 - stats.skipped_invalid;
        stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_point_rounds_to_nearest() {
        for x in [0.0, 1.0, -1.0, 0.3, -0.7, 1.5, -2.0, 1e-12, -3.2e-10] {
            assert_eq!(fixed_point(x), (x * SUM_SCALE).round() as i64, "{x}");
        }
    }

    #[test]
    fn kept_offsets_are_the_indices_the_sampler_keeps() {
        let s = Sampler::new(0.12).unwrap();
        let threshold = s.threshold.unwrap();
        let mut kept = [0u16; SAMPLE_BLOCK];
        for (first, len) in [
            (0, SAMPLE_BLOCK),
            (8192, 100),
            (u64::MAX - 7, SAMPLE_BLOCK),
            (5, 0),
        ] {
            let count = kept_offsets(threshold, first, len, &mut kept);
            let expected: Vec<u16> = (0..len as u16)
                .filter(|&o| s.keep(first.wrapping_add(u64::from(o))))
                .collect();
            assert_eq!(&kept[..count], expected.as_slice(), "{first} + {len}");
        }
    }

    /// Runs `driver` over `normals` into `bins` on a pool of `threads`, each normal
    /// binned into the cell given by its x coordinate.
    fn run_on(threads: usize, driver: Driver<'_>, normals: &[[f64; 3]], bins: &mut Bins) {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            driver.run(normals, bins, |batch, cells| {
                for (p, c) in batch.iter().zip(cells) {
                    *c = (p[0].abs() * 100.0) as u32;
                }
            })
        });
    }

    #[test]
    fn parallel_parts_add_up_to_the_sequential_bins_and_are_kept_empty() {
        let normals: Vec<[f64; 3]> = (0..50_000)
            .map(|i| {
                let x = f64::from(i % 97) / 100.0;
                [x, 0.0, (1.0 - x * x).sqrt()]
            })
            .collect();
        let mut sample = SampleCache::default();
        let kept = sample
            .kept(
                Sampler::new(0.5).unwrap(),
                normals.len(),
                Parallelism::Rayon,
            )
            .map(<[usize]>::to_vec);
        let driver = |parallelism| Driver {
            kept: kept.as_deref(),
            unit_tolerance: 1e-6,
            parallelism,
        };
        let mut sequential = Bins::new(100);
        run_on(
            1,
            driver(Parallelism::Sequential),
            &normals,
            &mut sequential,
        );
        let mut parallel = Bins::new(100);
        // Twice: the second run starts from the kept parts and adds to the bins.
        for run in 1..=2 {
            run_on(4, driver(Parallelism::Rayon), &normals, &mut parallel);
            assert_eq!(
                parallel.parts.len(),
                3,
                "one kept part per worker but the first"
            );
            assert!(
                parallel
                    .parts
                    .iter()
                    .all(|p| p.counts.iter().all(|&c| c == 0))
            );
            assert!(
                parallel
                    .parts
                    .iter()
                    .all(|p| p.sums.iter().all(|&s| s == [0; 3]))
            );
            let counts: Vec<u64> = sequential.counts.iter().map(|&c| c * run).collect();
            assert_eq!(parallel.counts, counts);
            let sums: Vec<[i64; 3]> = sequential
                .sums
                .iter()
                .map(|s| s.map(|v| v * run as i64))
                .collect();
            assert_eq!(parallel.sums, sums);
        }
        assert!(sequential.counts.iter().sum::<u64>() > 20_000);
    }

    /// The cached indices are those the sampler keeps (brute force, index by index)
    /// whatever the order of lengths asked for: growing in steps that are not whole blocks
    /// or chunks, shrinking, another fraction, sequential or parallel hashing.
    #[test]
    fn cached_sample_is_what_the_sampler_keeps_for_any_sequence_of_lengths() {
        let mut cache = SampleCache::default();
        let steps = [
            (0.12, 1000, Parallelism::Sequential),
            (0.12, 30_001, Parallelism::Rayon),
            (0.12, 777, Parallelism::Rayon),
            (0.12, 50_000, Parallelism::Sequential),
            (0.5, 20_000, Parallelism::Rayon),
            (0.12, 8192 * 3 + 1, Parallelism::Rayon),
            (0.12, 0, Parallelism::Sequential),
        ];
        for (fraction, len, parallelism) in steps {
            let sampler = Sampler::new(fraction).unwrap();
            let expected: Vec<usize> = (0..len).filter(|&i| sampler.keep(i as u64)).collect();
            let got = cache.kept(sampler, len, parallelism).unwrap();
            assert_eq!(got, expected.as_slice(), "{fraction} {len}");
        }
        assert_eq!(
            cache.kept(Sampler::new(1.0).unwrap(), 10, Parallelism::Rayon),
            None
        );
    }

    #[test]
    fn sampler_keeps_about_the_fraction() {
        let s = Sampler::new(0.12).unwrap();
        let kept = (0..100_000u64).filter(|&i| s.keep(i)).count();
        assert!((11_500..12_500).contains(&kept), "{kept}");
        let all = Sampler::new(1.0).unwrap();
        assert!((0..1000u64).all(|i| all.keep(i)));
        for bad in [0.0, -0.1, 1.5, f64::NAN] {
            assert!(matches!(
                Sampler::new(bad),
                Err(FastGaError::InvalidSampleFraction(_))
            ));
        }
    }
}
