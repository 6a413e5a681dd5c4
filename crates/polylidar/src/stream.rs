//! Streams of organized frames (an RGB-D camera's depth images, a range scanner's sweeps)
//! through one [`Polylidar`]: the pipeline, its thread pool, FastGA detector, smoothers
//! (the GPU context included) and segmentation buffers are kept from frame to frame,
//! frame `n + 1` is read and decoded on a loader thread while frame `n` runs, and, where
//! it pays ([`StreamOptions::in_flight`]), two frames run at once on the pipeline's
//! threads, so that one frame's sequential stretches leave no thread idle.
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
    /// Frames run at once on the pipeline's threads; 0 (the default) chooses: two when
    /// the pipeline refines its planes ([`crate::Config::refine`], the `-auto` presets),
    /// whose sequential stretches leave a thread idle that another frame then uses, else
    /// one. On a 2-core machine two at once took `rgbd-auto` streams of one frame
    /// repeated 14–28 % less time per frame (640 × 480, 848 × 480, 424 × 240), and
    /// `rgbd` streams, which keep both threads busy alone, 2–12 % more. Frames start in
    /// batches of this many, so a batch of frames of very different cost gains little.
    /// A frame comes out when the frames it ran with are done too, later than alone: 1
    /// gives the lowest latency. No more frames run at once than the pipeline has
    /// threads, nor than four (the sets of buffers a `Polylidar` keeps); one at a time
    /// with GPU smoothing (one device queue).
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
    in_flight: usize,
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
            _ if gpu || threads < 2 => 1,
            0 if config.refine => 2,
            0 => 1,
            n => n.min(threads).min(crate::reuse::KEPT),
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
        let mut batch = Vec::with_capacity(self.in_flight);
        while batch.len() < self.in_flight {
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
        let ran: Vec<_> = if batch.len() > 1 {
            polylidar.install(|| batch.into_par_iter().map(run).collect())
        } else {
            batch.into_iter().map(run).collect()
        };
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

    #[test]
    fn frames_come_in_order_with_their_errors_and_a_dropped_stream_stops() {
        let polylidar = Polylidar::new(Config::new().with_min_triangles(10)).expect("config");
        for (prefetch, in_flight) in [(0, 0), (1, 1), (2, 1), (0, 2), (1, 2), (1, 4)] {
            let sources: Vec<(String, usize)> = (0..6).map(|k| (format!("f{k}"), k)).collect();
            let load = |k: usize| {
                if k == 3 {
                    Err(PolylidarError::Config {
                        field: "frame",
                        value: k.to_string(),
                        reason: "unreadable",
                    })
                } else {
                    Ok(plane(10 + k, 12, k as f64))
                }
            };
            let options = StreamOptions::default()
                .with_prefetch(prefetch)
                .with_in_flight(in_flight);
            let frames: Vec<StreamedFrame> = polylidar.stream(sources, load, options).collect();
            assert_eq!(frames.len(), 6);
            for (k, frame) in frames.iter().enumerate() {
                assert_eq!(
                    (frame.index, frame.name.as_str()),
                    (k, format!("f{k}").as_str())
                );
                match &frame.extraction {
                    Ok(e) => {
                        assert_ne!(k, 3);
                        assert_eq!(e.mesh.vertices().len(), (10 + k) * 12);
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
