//! Streams of organized frames (an RGB-D camera's depth images, a range scanner's sweeps)
//! through one [`Polylidar`]: the pipeline, its thread pool, FastGA detector, smoothers
//! (the GPU context included) and segmentation buffers are kept from frame to frame,
//! frame `n + 1` is read and decoded on a loader thread while frame `n` runs, and, where
//! measuring shows that it pays ([`StreamOptions::in_flight`]), two frames run at once on
//! the pipeline's threads, so that one frame's sequential stretches leave no thread idle.
//!
//! ```
//! use polylidar::{Config, OrganizedPointCloud, Polylidar, PolylidarError};
//! use polylidar::stream::StreamOptions;
//!
//! // Three frames of the plane z = 1 + k, made by the loader from their number.
//! let frames: Vec<(String, usize)> = (0..3).map(|k| (format!("frame {k}"), k)).collect();
//! let load = |k: usize| -> Result<OrganizedPointCloud, PolylidarError> {
//!     let points = (0..400).map(|i| [(i % 20) as f64 * 0.1, (i / 20) as f64 * 0.1, 1.0 + k as f64]);
//!     Ok(OrganizedPointCloud::new(20, 20, points.collect())?)
//! };
//! let polylidar = Polylidar::new(Config::new().with_min_triangles(10))?;
//! for frame in polylidar.stream(frames, load, StreamOptions::default()) {
//!     let extraction = frame.extraction?;
//!     assert_eq!(extraction.polygons.len(), 1, "{}", frame.name);
//! }
//! # Ok::<(), PolylidarError>(())
//! ```

use std::collections::VecDeque;
use std::sync::mpsc::{Receiver, sync_channel};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::{Extraction, OrganizedPointCloud, Polylidar, PolylidarError};

/// How a stream runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct StreamOptions {
    /// Frames loaded ahead of the one the pipeline runs, on a loader thread (a bounded
    /// channel holds this many; one more may be being decoded); 0 loads each frame in
    /// the caller's thread when it is needed. Default 1: frame `n + 1` is read and decoded
    /// while frame `n` runs, and at most three frames are in memory.
    pub prefetch: usize,
    /// Frames run at once on the pipeline's threads; 0 (the default) chooses one or two
    /// by measuring. It starts with two where the pipeline refines its planes
    /// ([`crate::Config::refine`], the `-auto` presets), else with one. After 4 frames,
    /// and then every 256, it runs a trial: 8 frames with the count in use, 8 with the
    /// other, and again. The other count replaces the one in use if its 16 frames took
    /// at least 3 % less run time per frame.
    ///
    /// Two at once pay where a frame's sequential stretches leave a thread idle that the
    /// other frame then uses, and cost where one frame keeps both threads busy alone.
    /// Which way it goes depends on the frames and on the machine. On 2 cores two at
    /// once took:
    /// - `rgbd-auto` streams of one frame repeated: 14–28 % less time per frame
    ///   (640 × 480, 848 × 480, 424 × 240, Xeon);
    /// - `rgbd` streams of the RealSense 424 × 240 frame: 2–12 % more on the Xeon, 1–16 %
    ///   less (median of five runs 11 %) on an AMD EPYC with AVX2;
    /// - `rgbd` streams of a synthetic D435 424 × 240 frame with 30 mm noise, whose one
    ///   large polygon's buffers run on one thread: 36–39 % less (AMD EPYC).
    ///
    /// Frames start in batches of this many, so a batch of frames of very different
    /// cost gains little. A frame comes out when the frames it ran with are done too,
    /// later than alone: 1 gives the lowest latency. No more frames run at once than the
    /// pipeline has threads, nor than four (the sets of buffers a `Polylidar` keeps); one
    /// at a time with GPU smoothing (one device queue).
    pub in_flight: usize,
}

impl Default for StreamOptions {
    fn default() -> Self {
        Self {
            prefetch: 1,
            in_flight: 0,
        }
    }
}

impl StreamOptions {
    /// Sets [`Self::prefetch`].
    pub fn with_prefetch(mut self, prefetch: usize) -> Self {
        self.prefetch = prefetch;
        self
    }

    /// Sets [`Self::in_flight`] (0: chosen by the pipeline).
    pub fn with_in_flight(mut self, in_flight: usize) -> Self {
        self.in_flight = in_flight;
        self
    }
}

/// What a stream yields for each frame, in the order of its sources; `X` is what the
/// loader of [`Polylidar::stream_with`] hands over beside the cloud (a colour picture, a
/// timestamp).
#[derive(Debug)]
pub struct StreamedFrame<X = ()> {
    /// Position in the stream, from 0.
    pub index: usize,
    /// The frame's name, as given with its source.
    pub name: String,
    /// The pipeline's result, or why the frame could not be loaded or run.
    pub extraction: Result<Extraction, PolylidarError>,
    /// Reading and decoding the frame (on the loader thread when prefetching).
    pub load: Duration,
    /// How long the pipeline waited for the frame: the whole load without prefetching,
    /// near zero when the loader keeps ahead.
    pub wait: Duration,
    /// The pipeline run ([`Polylidar::extract_organized`]); its stages are in the
    /// extraction's [`crate::Timings`]. With frames in flight
    /// ([`StreamOptions::in_flight`]) the frame shared the threads with the others.
    pub run: Duration,
    /// What the loader returned beside the cloud; `None` when the load failed.
    pub extra: Option<X>,
}

/// A loaded frame: name, cloud and extra or error, load time.
type Loaded<X> = (
    String,
    Result<(OrganizedPointCloud, X), PolylidarError>,
    Duration,
);

/// Where the next loaded frame comes from.
enum Frames<X> {
    /// Loaded in the caller's thread.
    Inline(Box<dyn Iterator<Item = Loaded<X>> + Send>),
    /// Loaded ahead on a thread.
    Thread {
        frames: Option<Receiver<Loaded<X>>>,
        loader: Option<JoinHandle<()>>,
    },
}

impl<X> Frames<X> {
    /// The next loaded frame; `None` at the end of the stream.
    fn next(&mut self) -> Option<Loaded<X>> {
        match self {
            Self::Inline(loads) => loads.next(),
            Self::Thread { frames, .. } => frames.as_ref()?.recv().ok(),
        }
    }
}

/// The iterator of [`Polylidar::stream`] and [`Polylidar::stream_with`].
pub struct FrameStream<'p, X = ()> {
    polylidar: &'p Polylidar,
    frames: Frames<X>,
    /// Frames run at once (see [`StreamOptions::in_flight`]).
    in_flight: InFlight,
    /// Frames run and not yet handed out, in order.
    done: VecDeque<StreamedFrame<X>>,
    index: usize,
}

impl<X> std::fmt::Debug for FrameStream<'_, X> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameStream")
            .field("index", &self.index)
            .field("prefetching", &matches!(self.frames, Frames::Thread { .. }))
            .finish_non_exhaustive()
    }
}

impl Polylidar {
    /// Runs the organized pipeline on a stream of frames: `sources` are `(name, source)`
    /// pairs in the order to run them, `load` turns a source into its cloud (reading and
    /// decoding a file, back-projecting a depth image). With
    /// [`StreamOptions::prefetch`] > 0 the loads run on a loader thread, ahead of the
    /// pipeline by up to that many frames. Each frame's result is that of
    /// [`Self::extract_organized`] on its cloud alone; a frame that fails to load or run
    /// yields its error and the stream goes on. Dropping the iterator stops the loader.
    pub fn stream<S, L>(
        &self,
        sources: Vec<(String, S)>,
        mut load: L,
        options: StreamOptions,
    ) -> FrameStream<'_>
    where
        S: Send + 'static,
        L: FnMut(S) -> Result<OrganizedPointCloud, PolylidarError> + Send + 'static,
    {
        self.stream_with(sources, move |s| load(s).map(|c| (c, ())), options)
    }

    /// [`Self::stream`] with a loader that returns something beside each cloud (`X`, a
    /// colour picture, a timestamp), handed over in [`StreamedFrame::extra`].
    pub fn stream_with<S, L, X>(
        &self,
        sources: Vec<(String, S)>,
        mut load: L,
        options: StreamOptions,
    ) -> FrameStream<'_, X>
    where
        S: Send + 'static,
        X: Send + 'static,
        L: FnMut(S) -> Result<(OrganizedPointCloud, X), PolylidarError> + Send + 'static,
    {
        let loads = sources.into_iter().map(move |(name, source)| {
            let start = Instant::now();
            let cloud = load(source);
            (name, cloud, start.elapsed())
        });
        let frames = if options.prefetch == 0 {
            Frames::Inline(Box::new(loads))
        } else {
            let (sender, receiver) = sync_channel(options.prefetch);
            let loader = std::thread::spawn(move || {
                for loaded in loads {
                    if sender.send(loaded).is_err() {
                        break; // the stream was dropped
                    }
                }
            });
            Frames::Thread {
                frames: Some(receiver),
                loader: Some(loader),
            }
        };
        let config = self.config();
        let gpu = [
            config.laplacian.as_ref().map(|l| l.backend),
            config.bilateral.as_ref().map(|b| b.backend),
        ]
        .contains(&Some(crate::SmoothingBackend::Gpu));
        let threads = self.threads();
        let in_flight = match options.in_flight {
            _ if gpu || threads < 2 => InFlight::Fixed(1),
            0 => InFlight::Measured(Chooser::new(if config.refine { 2 } else { 1 })),
            n => InFlight::Fixed(n.min(threads).min(crate::reuse::KEPT)),
        };
        FrameStream {
            polylidar: self,
            frames,
            in_flight,
            done: VecDeque::new(),
            index: 0,
        }
    }
}

impl<X: Send> Iterator for FrameStream<'_, X> {
    type Item = StreamedFrame<X>;

    fn next(&mut self) -> Option<StreamedFrame<X>> {
        if self.done.is_empty() {
            self.run_next();
        }
        self.done.pop_front()
    }
}

impl<X: Send> FrameStream<'_, X> {
    /// Runs the next frames, up to [`Self::in_flight`] of them at once, into `done`.
    fn run_next(&mut self) {
        let in_flight = match &self.in_flight {
            InFlight::Fixed(n) => *n,
            InFlight::Measured(chooser) => chooser.batch(),
        };
        let mut batch = Vec::with_capacity(in_flight);
        while batch.len() < in_flight {
            let start = Instant::now();
            let Some(loaded) = self.frames.next() else {
                break;
            };
            batch.push((loaded, start.elapsed()));
        }
        let polylidar = self.polylidar;
        let run = |((name, cloud, load), wait): (Loaded<X>, Duration)| {
            let start = Instant::now();
            let (extraction, extra) = match cloud {
                Ok((cloud, extra)) => (polylidar.extract_organized(&cloud), Some(extra)),
                Err(e) => (Err(e), None),
            };
            (name, extraction, extra, load, wait, start.elapsed())
        };
        let (frames, start) = (batch.len(), Instant::now());
        let ran: Vec<_> = if batch.len() > 1 {
            polylidar.install(|| batch.into_par_iter().map(run).collect())
        } else {
            batch.into_iter().map(run).collect()
        };
        // Past the last frame the batch is empty: nothing to time.
        if let (InFlight::Measured(chooser), 1..) = (&mut self.in_flight, frames) {
            chooser.record(frames, start.elapsed());
        }
        for (name, extraction, extra, load, wait, run) in ran {
            self.done.push_back(StreamedFrame {
                index: self.index,
                name,
                extraction,
                load,
                wait,
                run,
                extra,
            });
            self.index += 1;
        }
    }
}

/// How many frames a stream runs at once: as asked, or chosen by measuring.
#[derive(Debug)]
enum InFlight {
    Fixed(usize),
    Measured(Chooser),
}

/// Frames per window of a [`Chooser`]'s trial.
const TRIAL_WINDOW: usize = 8;
/// Frames a [`Chooser`] runs before its first trial: the first frames also size the
/// pipeline's buffers.
const FIRST_TRIAL_AFTER: usize = 4;
/// Frames between the end of one trial of a [`Chooser`] and the next: the scene, and
/// with it what pays, may change.
const TRIAL_EVERY: usize = 256;
/// How much less time per frame the count not in use must take in a trial to replace
/// the one in use.
const SWITCH_GAIN: f64 = 0.03;

/// Chooses between running one frame at a time and two, by the run time per frame.
/// After [`FIRST_TRIAL_AFTER`] frames, and then every [`TRIAL_EVERY`], a trial runs
/// four windows of [`TRIAL_WINDOW`] frames: the count in use, the other, the count in
/// use, the other. The two windows of each count are added up, so that a slow moment of
/// the machine weighs on both. The other count replaces the one in use only if it took
/// [`SWITCH_GAIN`] less time per frame.
#[derive(Debug, Clone)]
struct Chooser {
    /// The count in use outside trials: 1 or 2.
    current: usize,
    /// Frames to run before the next trial.
    until_trial: usize,
    trial: Option<Trial>,
}

/// A trial under way: the windows left, last one first, and per count (1, 2) the run
/// time and frames measured.
#[derive(Debug, Clone)]
struct Trial {
    windows: Vec<usize>,
    left_in_window: usize,
    time: [Duration; 2],
    frames: [usize; 2],
}

impl Chooser {
    /// A chooser that starts with `first` (1 or 2) frames at a time.
    fn new(first: usize) -> Self {
        Self {
            current: first.clamp(1, 2),
            until_trial: FIRST_TRIAL_AFTER,
            trial: None,
        }
    }

    /// How many frames to run at once next.
    fn batch(&self) -> usize {
        match &self.trial {
            Some(trial) => trial.windows.last().copied().unwrap_or(self.current),
            None => self.current,
        }
    }

    /// Counts `frames` frames run at once in `run`.
    fn record(&mut self, frames: usize, run: Duration) {
        let Some(trial) = &mut self.trial else {
            self.until_trial = self.until_trial.saturating_sub(frames);
            if self.until_trial == 0 {
                let other = 3 - self.current;
                self.trial = Some(Trial {
                    windows: vec![other, self.current, other, self.current],
                    left_in_window: TRIAL_WINDOW,
                    time: [Duration::ZERO; 2],
                    frames: [0; 2],
                });
            }
            return;
        };
        let Some(&count) = trial.windows.last() else {
            return;
        };
        trial.time[count - 1] += run;
        trial.frames[count - 1] += frames;
        trial.left_in_window = trial.left_in_window.saturating_sub(frames);
        if trial.left_in_window > 0 {
            return;
        }
        trial.windows.pop();
        trial.left_in_window = TRIAL_WINDOW;
        if !trial.windows.is_empty() {
            return;
        }
        let per_frame =
            |c: usize| trial.time[c - 1].as_secs_f64() / trial.frames[c - 1].max(1) as f64;
        let other = 3 - self.current;
        if per_frame(other) < (1.0 - SWITCH_GAIN) * per_frame(self.current) {
            self.current = other;
        }
        self.trial = None;
        self.until_trial = TRIAL_EVERY;
    }
}

impl<X> Drop for FrameStream<'_, X> {
    fn drop(&mut self) {
        if let Frames::Thread { frames, loader } = &mut self.frames {
            // Closing the channel makes the loader's next send fail, so it stops.
            drop(frames.take());
            if let Some(loader) = loader.take() {
                // A loader that panicked has nothing left to hand over.
                let _ = loader.join();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Config;

    fn plane(rows: usize, cols: usize, z: f64) -> OrganizedPointCloud {
        let points = (0..rows * cols)
            .map(|i| [(i % cols) as f64 * 0.1, (i / cols) as f64 * 0.1, z])
            .collect();
        OrganizedPointCloud::new(rows, cols, points).expect("a full grid")
    }

    /// Runs `frames` frames through `chooser`, a frame at `count` at once taking
    /// `per_frame(count, frame)`; returns the counts it ran, a batch at a time.
    fn choose(
        chooser: &mut Chooser,
        frames: std::ops::Range<usize>,
        per_frame: impl Fn(usize, usize) -> f64,
    ) -> Vec<usize> {
        let mut batches = Vec::new();
        let mut frame = frames.start;
        while frame < frames.end {
            let count = chooser.batch();
            let n = count.min(frames.end - frame);
            chooser.record(
                n,
                Duration::from_secs_f64(n as f64 * per_frame(count, frame)),
            );
            batches.push(count);
            frame += n;
        }
        batches
    }

    #[test]
    fn the_chooser_keeps_the_count_that_takes_less_time_per_frame() {
        // Two at once 10 % faster: after the warm-up frames and the trial (4 windows of
        // 8 frames: one, two, one, two at a time), it runs two at a time.
        let mut chooser = Chooser::new(1);
        let batches = choose(&mut chooser, 0..36, |count, _| [1.0, 0.9][count - 1]);
        assert_eq!(&batches[..4], &[1; 4]);
        assert_eq!(&batches[4..12], &[1; 8]);
        assert_eq!(&batches[12..16], &[2; 4]);
        assert_eq!(&batches[16..24], &[1; 8]);
        assert_eq!(&batches[24..28], &[2; 4]);
        assert_eq!(chooser.batch(), 2);
        // Within 3 %: the count in use stays.
        let mut chooser = Chooser::new(2);
        choose(&mut chooser, 0..36, |count, _| [0.98, 1.0][count - 1]);
        assert_eq!(chooser.batch(), 2);
        // A slow moment of the machine (30 % slower) through the first window of one at a
        // time is not enough to keep two, which are 20 % slower: the trial adds up both
        // windows of each count.
        let mut chooser = Chooser::new(2);
        let slow = |count: usize, frame: usize| {
            let base = [1.0, 1.2][count - 1];
            if (12..20).contains(&frame) {
                1.3 * base
            } else {
                base
            }
        };
        choose(&mut chooser, 0..36, slow);
        assert_eq!(chooser.batch(), 1);
        // The next trial, 256 frames later, follows a change of scene.
        let batches = choose(&mut chooser, 36..36 + 256 + 32, |count, _| {
            [1.0, 0.5][count - 1]
        });
        assert!(batches[..256].iter().all(|&c| c == 1));
        assert_eq!(chooser.batch(), 2);
    }

    #[test]
    fn frames_come_in_order_with_their_errors_and_a_dropped_stream_stops() {
        let polylidar = Polylidar::new(Config::new().with_min_triangles(10)).expect("config");
        // The 40 frames with a count chosen by measuring run a trial, one and two at once.
        for (prefetch, in_flight, count) in [
            (0, 0, 6),
            (1, 0, 40),
            (1, 1, 6),
            (2, 1, 6),
            (0, 2, 6),
            (1, 2, 6),
            (1, 4, 6),
        ] {
            let sources: Vec<(String, usize)> = (0..count).map(|k| (format!("f{k}"), k)).collect();
            let load = |k: usize| {
                if k == 3 {
                    Err(PolylidarError::Config {
                        field: "frame",
                        value: k.to_string(),
                        reason: "unreadable",
                    })
                } else {
                    Ok(plane(10 + k % 6, 12, k as f64))
                }
            };
            let options = StreamOptions::default()
                .with_prefetch(prefetch)
                .with_in_flight(in_flight);
            let frames: Vec<StreamedFrame> = polylidar.stream(sources, load, options).collect();
            assert_eq!(frames.len(), count);
            for (k, frame) in frames.iter().enumerate() {
                assert_eq!(
                    (frame.index, frame.name.as_str()),
                    (k, format!("f{k}").as_str())
                );
                match &frame.extraction {
                    Ok(e) => {
                        assert_ne!(k, 3);
                        assert_eq!(e.mesh.vertices().len(), (10 + k % 6) * 12);
                        assert_eq!(e.polygons[0].plane.centroid[2], k as f64);
                    }
                    Err(e) => assert_eq!(k, 3, "{e}"),
                }
            }
            // Taking two frames of a long stream and dropping it ends the loader.
            let many: Vec<(String, usize)> = (0..1000).map(|k| (k.to_string(), k)).collect();
            let taken = polylidar
                .stream(many, |k| Ok(plane(4, 4, k as f64)), options)
                .take(2)
                .count();
            assert_eq!(taken, 2);
        }
    }
}
