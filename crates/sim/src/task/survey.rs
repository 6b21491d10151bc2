//! What a task's latent space offers before any training (`latentrl check`): a grid over the
//! latent box at the learner's own step, each point decoded and put at rest through the task's
//! plant (the rule it breaks, its reward, its distance to the target, whether it is within the
//! reach radius), and the fewest learner moves from each point to one within the reach radius
//! through admissible points.
//!
//! A move is judged at rest: it is allowed when the point it lands on is an admissible posture.
//! With `physics`, each move from each admissible point is also run through the task's physics
//! from rest there (the learner's targets along it, one RL step each) and is blocked when a rule
//! breaks on the way (a swing through an obstacle between two clear postures, a held object
//! tipped in transit). A path either way is necessary for learning, not sufficient (the learner
//! moves from where it is, not from rest); a start with no path has none in training either, up
//! to the grid.
//!
//! A grid kept within its point budget runs at a stride of several learner steps, and a target
//! region smaller than one of its cells falls between its points. So at a stride > 1 the cells
//! where the region can be are looked into again at the learner's own step: the cells of the
//! decoder's inputs (the demos' latent points, where the data is) and of the points closest to
//! the target, closest first, within the grid's own budget. The region's size and the closest
//! point come from there; a cell with a reached point counts as reached for the paths.

use std::collections::VecDeque;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use latent_core::gp::GpMap;
use latent_core::trials::LatentArgs;
use latent_core::{Learner, Plant, ResultArray};
use rayon::prelude::*;

use super::{Task, TaskPlant};
use crate::error::Result;

/// Points a grid holds at most by default: ≈ 10 s of resets on two cores for a floating robot.
pub const DEFAULT_MAX_POINTS: usize = 20_000;

/// Points classified between two looks at the cancel flag.
const CHUNK: usize = 64;

/// The most learner steps one grid move may span. A smaller learner step is refused: the
/// physics of each move and the cells looked into grow with the steps a move spans (a step of
/// 10⁻⁶ spacings ran for hours, its cells would not fit in memory, 10⁻³⁰⁰ overflowed the grid).
pub const MAX_STRIDE: usize = 64;

/// Cells looked into again at the learner's step besides the demos': the admissible points
/// closest to the target.
const REFINED_CLOSEST: usize = 16;

/// A regular grid over a latent box, row-major (the last dimension fastest).
#[derive(Debug, Clone, PartialEq)]
pub struct LatentGrid {
    low: Vec<f64>,
    spacing: Vec<f64>,
    shape: Vec<usize>,
    stride: usize,
}

impl LatentGrid {
    /// The grid over `[low, high]` whose spacing is `stride` learner steps (`step[k]` per
    /// dimension), `stride` the smallest ≥ 1 that keeps at most `max_points` points.
    pub fn at_step(low: &[f64], high: &[f64], step: &[f64], max_points: usize) -> Self {
        let shape_at = |stride: usize| -> Vec<usize> {
            low.iter()
                .zip(high)
                .zip(step)
                .map(|((lo, hi), s)| (((hi - lo) / (stride as f64 * s) + 1e-9).floor() as usize).saturating_add(1))
                .collect()
        };
        let points = |shape: Vec<usize>| shape.iter().fold(1usize, |n, &k| n.saturating_mul(k));
        let mut stride = 1;
        while stride < usize::MAX / 2 && points(shape_at(stride)) > max_points.max(1) {
            stride += 1;
        }
        Self {
            low: low.to_vec(),
            spacing: step.iter().map(|s| stride as f64 * s).collect(),
            shape: shape_at(stride),
            stride,
        }
    }

    /// Every point, row-major (`len() × d` values).
    pub fn points(&self) -> Vec<f64> {
        let d = self.shape.len();
        let mut points = vec![0.0; self.len() * d];
        for (i, p) in points.chunks_exact_mut(d).enumerate() {
            self.point(i, p);
        }
        points
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.shape.iter().product()
    }

    /// Whether it has no point (never: every dimension has at least one).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Points per dimension.
    pub fn shape(&self) -> &[usize] {
        &self.shape
    }

    /// Learner steps between neighbouring points.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// Distance between neighbouring points per dimension.
    pub fn spacing(&self) -> &[f64] {
        &self.spacing
    }

    /// The point of `index` into `out`.
    pub fn point(&self, mut index: usize, out: &mut [f64]) {
        for k in (0..self.shape.len()).rev() {
            out[k] = self.low[k] + (index % self.shape[k]) as f64 * self.spacing[k];
            index /= self.shape[k];
        }
    }

    /// The index of the point nearest `z` (clamped into the grid).
    fn nearest(&self, z: &[f64]) -> usize {
        let mut index = 0;
        for (k, z) in z.iter().enumerate() {
            let at = ((z - self.low[k]) / self.spacing[k])
                .round()
                .clamp(0.0, (self.shape[k] - 1) as f64);
            index = index * self.shape[k] + at as usize;
        }
        index
    }

    /// The points one learner step apart in the cell of point `index` (offsets of
    /// −⌊stride/2⌋ … stride − ⌊stride/2⌋ − 1 steps per dimension around it, the cells tiling
    /// the grid), within the grid's span, flat, `dim` values each.
    fn cell(&self, index: usize) -> Vec<f64> {
        let d = self.shape.len();
        let s = self.stride as i64;
        let mut centre = vec![0.0; d];
        self.point(index, &mut centre);
        let mut out = Vec::new();
        let mut offset = vec![-(s / 2); d];
        loop {
            let z: Vec<f64> = (0..d)
                .map(|k| centre[k] + offset[k] as f64 * self.spacing[k] / s as f64)
                .collect();
            let last = |k: usize| self.low[k] + (self.shape[k] - 1) as f64 * self.spacing[k];
            if z.iter()
                .enumerate()
                .all(|(k, v)| *v >= self.low[k] - 1e-12 && *v <= last(k) + 1e-12)
            {
                out.extend(z);
            }
            let Some(k) = (0..d).rev().find(|&k| offset[k] < s - s / 2 - 1) else {
                return out;
            };
            offset[k] += 1;
            offset[k + 1..].fill(-(s / 2));
        }
    }

    /// The index `offset` points away from `index`, if inside the grid.
    fn neighbour(&self, index: usize, offset: &[i64]) -> Option<usize> {
        let (mut rest, mut out, mut scale) = (index, 0, 1);
        for k in (0..self.shape.len()).rev() {
            let at = (rest % self.shape[k]) as i64 + offset[k];
            rest /= self.shape[k];
            if at < 0 || at >= self.shape[k] as i64 {
                return None;
            }
            out += at as usize * scale;
            scale *= self.shape[k];
        }
        Some(out)
    }
}

/// A task's latent space at rest, point by point of a [`LatentGrid`].
#[derive(Debug, Clone)]
pub struct Survey {
    /// The grid.
    pub grid: LatentGrid,
    /// Per point: the code of the rule its decoded posture breaks at rest (0: none; 1 obstacle,
    /// 2 outside the joint limits, 3 drop, 4 fall).
    pub codes: Vec<u8>,
    /// Per point: the reward at rest.
    pub reward: Vec<f64>,
    /// Per point: the RMS effector distance to the target at rest (m).
    pub distance: Vec<f64>,
    /// Per point: admissible and within the reach radius.
    pub reached: Vec<bool>,
    /// Per point: the effector positions at rest, (x, y, z) per effector.
    pub effectors: Vec<f64>,
    /// Per point: the fewest learner moves (grid moves × stride) to a reached point through
    /// admissible points; `None` if there is no such path (or the point is not admissible).
    pub moves_to_target: Vec<Option<usize>>,
    /// With `physics`: per point and move (point-major), whether the move broke a rule on the
    /// way, run from rest; empty without.
    pub blocked: Vec<bool>,
    /// With `physics`: [`Survey::moves_to_target`] through the moves that broke no rule.
    pub moves_in_physics: Vec<Option<usize>>,
    /// Admissible points one learner step apart within the reach radius: the reached points at
    /// stride 1; at a larger stride those found in the cells looked into again, plus
    /// strideᵈ for each reached point whose cell was not.
    pub region_points: usize,
    /// The admissible point closest to the target found at either resolution, if any.
    pub closest: Option<Closest>,
}

/// What a [`Survey`] found beyond its per-point arrays, by name: the grid's shape, stride and
/// spacing, the target region's size and the closest point (left out if none).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SurveySummary {
    /// Points per dimension.
    pub shape: Vec<usize>,
    /// Learner steps between neighbouring points.
    pub stride: usize,
    /// Distance between neighbouring points per dimension.
    pub spacing: Vec<f64>,
    /// [`Survey::region_points`].
    pub region_points: usize,
    /// [`Survey::closest`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closest: Option<Closest>,
}

impl Survey {
    /// The per-point arrays by name: `points` (M, d), `codes`, `reward`, `distance`, `reached`
    /// (M,), `effectors` (M, 3E), `moves` and `moves_in_physics` (fewest moves, -1 for none),
    /// `blocked` (M·A,).
    pub fn arrays(&self) -> Vec<(String, ResultArray)> {
        let (m, d) = (self.grid.len(), self.grid.shape().len());
        let moves = |v: &[Option<usize>]| {
            let v: Vec<i64> = v.iter().map(|x| x.map_or(-1, |n| n as i64)).collect();
            let n = v.len();
            ResultArray::I64(v, vec![n])
        };
        vec![
            ("points".into(), ResultArray::F64(self.grid.points(), vec![m, d])),
            ("codes".into(), ResultArray::U8(self.codes.clone(), vec![m])),
            ("reward".into(), ResultArray::F64(self.reward.clone(), vec![m])),
            ("distance".into(), ResultArray::F64(self.distance.clone(), vec![m])),
            ("reached".into(), ResultArray::Bool(self.reached.clone(), vec![m])),
            (
                "effectors".into(),
                ResultArray::F64(self.effectors.clone(), vec![m, self.effectors.len() / m.max(1)]),
            ),
            ("moves".into(), moves(&self.moves_to_target)),
            ("moves_in_physics".into(), moves(&self.moves_in_physics)),
            (
                "blocked".into(),
                ResultArray::Bool(self.blocked.clone(), vec![self.blocked.len()]),
            ),
        ]
    }

    /// The grid and the target region found, by name.
    pub fn summary(&self) -> SurveySummary {
        SurveySummary {
            shape: self.grid.shape().to_vec(),
            stride: self.grid.stride(),
            spacing: self.grid.spacing().to_vec(),
            region_points: self.region_points,
            closest: self.closest.clone(),
        }
    }
}

/// An admissible latent point and what its decoded posture gives at rest.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Closest {
    /// The latent point.
    pub point: Vec<f64>,
    /// The RMS effector distance to the target (m).
    pub distance: f64,
    /// The reward.
    pub reward: f64,
    /// The effector positions, (x, y, z) per effector.
    pub effectors: Vec<f64>,
}

/// The grid of a [`TaskSurvey`] and the learner's moves on it.
#[derive(Debug, Clone, PartialEq)]
pub struct LearnerGrid {
    /// The grid, at the learner's step (or `stride` of them).
    pub grid: LatentGrid,
    /// The learner's moves as unit offsets on the grid (one grid move = `stride` learner moves).
    pub moves: Vec<Vec<i64>>,
}

impl LearnerGrid {
    /// The grid over `[low, high]` at `task`'s learner step with at most `max_points` points.
    pub fn new(task: &Task, low: &[f64], high: &[f64], max_points: usize) -> Result<Self> {
        let learner = Learner::new(&task.config().learner, task.episode_rules(), low, high)
            .map_err(|e| task.error(e.to_string()))?;
        let d = low.len();
        // The learner's step per dimension: its largest move along each axis.
        let displacements = learner.displacements();
        let step: Vec<f64> = (0..d)
            .map(|k| displacements.chunks_exact(d).map(|m| m[k].abs()).fold(0.0, f64::max))
            .collect();
        let fits = |k: usize| (high[k] - low[k]) / (MAX_STRIDE as f64 * step[k]) + 1.0;
        if (0..d).map(fits).product::<f64>() > max_points.max(1) as f64 {
            let steps = (0..d).map(|k| (high[k] - low[k]) / step[k]).fold(0.0, f64::max);
            return Err(task.error(format!(
                "learner.step = {:e}: the latent box is {steps:.3e} learner steps wide, more than a survey \
                     samples ({max_points} points at most {MAX_STRIDE} learner steps apart); give a larger \
                     learner.step",
                task.config().learner.step
            )));
        }
        let moves = displacements
            .chunks_exact(d)
            .map(|m| {
                m.iter()
                    .zip(&step)
                    .map(|(x, s)| if x.abs() > 0.5 * s { x.signum() as i64 } else { 0 })
                    .collect()
            })
            .collect();
        Ok(Self {
            grid: LatentGrid::at_step(low, high, &step, max_points),
            moves,
        })
    }
}

/// A survey of a task's latent space ready to run: what `latentrl check` asks for, in one
/// object so that a caller can learn its size (for progress) before running it.
pub struct TaskSurvey<'a> {
    task: Arc<Task>,
    demos: Option<&'a [Vec<f64>]>,
    decoder: &'a GpMap,
    at: LearnerGrid,
    physics: bool,
}

impl<'a> TaskSurvey<'a> {
    /// The survey of `task`'s latent space given by `latent` (its decoder and box, checked by
    /// [`LatentArgs::check_box`]) on a grid of at most `max_points` points at the learner's
    /// step, each move also through the physics with `physics`; `demos` as for
    /// [`TaskPlant::new`] (a plant of them must build).
    pub fn new(
        task: Arc<Task>,
        demos: Option<&'a [Vec<f64>]>,
        latent: LatentArgs<'a>,
        max_points: usize,
        physics: bool,
    ) -> Result<Self> {
        let (decoder, low, high) = latent.check_box("")?;
        TaskPlant::new(Arc::clone(&task), demos)?;
        let at = LearnerGrid::new(&task, &low, &high, max_points)?;
        #[rustfmt::skip]
        return Ok(Self { task, demos, decoder, at, physics });
    }

    /// The points the survey classifies (what `done` counts to).
    pub fn points(&self) -> usize {
        self.at.grid.len()
    }

    /// Runs the survey: points are classified in parallel, `done` counts them and `cancel`
    /// stops the survey (an error).
    pub fn run(&self, cancel: &AtomicBool, done: &AtomicUsize) -> Result<Survey> {
        survey(
            &self.task,
            self.demos,
            self.decoder,
            &self.at,
            self.physics,
            cancel,
            done,
        )
    }
}

/// Surveys `task`'s latent space of `decoder` on `at` (its grid and the learner's moves), each
/// move also through the physics with `physics` ([`TaskSurvey::run`]).
fn survey(
    task: &Arc<Task>,
    demos: Option<&[Vec<f64>]>,
    decoder: &GpMap,
    at: &LearnerGrid,
    physics: bool,
    cancel: &AtomicBool,
    done: &AtomicUsize,
) -> Result<Survey> {
    let grid = &at.grid;
    let d = grid.shape().len();
    if decoder.input_dim() != d || decoder.output_dim() != task.model().joints().len() {
        return Err(task.error(format!(
            "the decoder maps {} → {} values; the survey needs {d} → {} (the robot's joints)",
            decoder.input_dim(),
            decoder.output_dim(),
            task.model().joints().len()
        )));
    }
    let n = grid.len();
    let e = 3 * task.config().effectors.len();
    let chunks: Vec<usize> = (0..n).step_by(CHUNK).collect();
    let parts = chunks
        .par_iter()
        .map_init(
            || TaskPlant::new(Arc::clone(task), demos),
            |plant, &start| {
                let plant = plant.as_mut().map_err(|err| task.error(err.to_string()))?;
                if cancel.load(Ordering::Relaxed) {
                    return Err(task.error("the survey was cancelled"));
                }
                let (mut z, mut q) = (vec![0.0; d], vec![0.0; decoder.output_dim()]);
                let mut scratch = decoder.scratch();
                let end = (start + CHUNK).min(n);
                let mut part = Part::default();
                for i in start..end {
                    if physics && cancel.load(Ordering::Relaxed) {
                        return Err(task.error("the survey was cancelled"));
                    }
                    grid.point(i, &mut z);
                    decoder.mean_into(&z, &mut q, &mut scratch);
                    let code = plant.reset(&q).map_or(0, |r| r.code());
                    part.codes.push(code);
                    part.reward.push(plant.reward());
                    part.distance.push(plant.rms_distance());
                    part.reached.push(code == 0 && plant.reached_target());
                    part.effectors.extend_from_slice(&plant.effectors()[..e]);
                    if physics {
                        for offset in &at.moves {
                            let blocked = code != 0 || breaks_on_the_way(plant, decoder, grid, i, offset, &mut scratch);
                            part.blocked.push(blocked);
                        }
                    }
                }
                done.fetch_add(end - start, Ordering::Relaxed);
                Ok(part)
            },
        )
        .collect::<Result<Vec<Part>>>()?;
    let mut all = Part::default();
    for p in parts {
        all.codes.extend(p.codes);
        all.reward.extend(p.reward);
        all.distance.extend(p.distance);
        all.reached.extend(p.reached);
        all.effectors.extend(p.effectors);
        all.blocked.extend(p.blocked);
    }
    let closest = (0..n)
        .filter(|&i| all.codes[i] == 0)
        .min_by(|&a, &b| all.distance[a].total_cmp(&all.distance[b]))
        .map(|i| closest_of(grid, &all, i, e));
    let (region_points, closest) = if grid.stride() > 1 {
        refine(task, demos, decoder, grid, &mut all, closest, cancel)?
    } else {
        (all.reached.iter().filter(|r| **r).count(), closest)
    };
    let moves_to_target = fewest_moves(grid, &all.codes, &all.reached, &at.moves, &[]);
    let moves_in_physics = if physics {
        fewest_moves(grid, &all.codes, &all.reached, &at.moves, &all.blocked)
    } else {
        Vec::new()
    };
    Ok(Survey {
        moves_to_target,
        moves_in_physics,
        blocked: all.blocked,
        codes: all.codes,
        reward: all.reward,
        distance: all.distance,
        reached: all.reached,
        effectors: all.effectors,
        grid: grid.clone(),
        region_points,
        closest,
    })
}

/// Point `i` of the grid's survey as a [`Closest`].
fn closest_of(grid: &LatentGrid, all: &Part, i: usize, e: usize) -> Closest {
    let mut point = vec![0.0; grid.shape().len()];
    grid.point(i, &mut point);
    Closest {
        point,
        distance: all.distance[i],
        reward: all.reward[i],
        effectors: all.effectors[i * e..(i + 1) * e].to_vec(),
    }
}

/// Looks into cells of a grid at a stride > 1 again at the learner's step (module docs): the
/// cells of the decoder's inputs and of the `REFINED_CLOSEST` admissible points closest to the
/// target, closest first, at most as many points as the grid has. Marks the cells with a reached
/// point reached in `all`; returns the region's points and the closest admissible point, the
/// grid's `closest` unless a cell holds a closer one.
fn refine(
    task: &Arc<Task>,
    demos: Option<&[Vec<f64>]>,
    decoder: &GpMap,
    grid: &LatentGrid,
    all: &mut Part,
    mut closest: Option<Closest>,
    cancel: &AtomicBool,
) -> Result<(usize, Option<Closest>)> {
    let (n, d) = (grid.len(), grid.shape().len());
    let e = 3 * task.config().effectors.len();
    let mut admissible: Vec<usize> = (0..n).filter(|&i| all.codes[i] == 0).collect();
    admissible.sort_by(|&a, &b| all.distance[a].total_cmp(&all.distance[b]).then(a.cmp(&b)));
    let mut cells: Vec<usize> = decoder
        .inputs()
        .column_iter()
        .map(|z| grid.nearest(z.as_slice()))
        .collect();
    cells.extend(admissible.iter().take(REFINED_CLOSEST));
    cells.sort_by(|&a, &b| all.distance[a].total_cmp(&all.distance[b]).then(a.cmp(&b)));
    cells.dedup();
    cells.truncate((n / grid.stride().pow(d as u32)).max(1));
    let found = cells
        .par_iter()
        .map_init(
            || TaskPlant::new(Arc::clone(task), demos),
            |plant, &cell| {
                let plant = plant.as_mut().map_err(|err| task.error(err.to_string()))?;
                if cancel.load(Ordering::Relaxed) {
                    return Err(task.error("the survey was cancelled"));
                }
                let mut q = vec![0.0; decoder.output_dim()];
                let mut scratch = decoder.scratch();
                let (mut reached, mut best): (usize, Option<Closest>) = (0, None);
                for z in grid.cell(cell).chunks_exact(d) {
                    decoder.mean_into(z, &mut q, &mut scratch);
                    if plant.reset(&q).is_some() {
                        continue;
                    }
                    reached += usize::from(plant.reached_target());
                    let distance = plant.rms_distance();
                    if best.as_ref().is_none_or(|b| distance < b.distance) {
                        best = Some(Closest {
                            point: z.to_vec(),
                            distance,
                            reward: plant.reward(),
                            effectors: plant.effectors()[..e].to_vec(),
                        });
                    }
                }
                Ok((reached, best))
            },
        )
        .collect::<Result<Vec<_>>>()?;
    let mut looked = vec![false; n];
    let mut region = 0;
    for (&cell, (reached, best)) in cells.iter().zip(found) {
        looked[cell] = true;
        region += reached;
        all.reached[cell] |= reached > 0;
        if let Some(b) = best
            && closest.as_ref().is_none_or(|c| b.distance < c.distance)
        {
            closest = Some(b);
        }
    }
    let unlooked = (0..n).filter(|&i| all.reached[i] && !looked[i]).count();
    Ok((region + unlooked * grid.stride().pow(d as u32), closest))
}

/// Whether the move `offset` from point `index`, run from rest there through the plant (one RL
/// step per learner step, towards the decoded points along it), breaks a rule on the way.
fn breaks_on_the_way(
    plant: &mut TaskPlant,
    decoder: &GpMap,
    grid: &LatentGrid,
    index: usize,
    offset: &[i64],
    scratch: &mut latent_core::gp::PredictScratch,
) -> bool {
    let Some(next) = grid.neighbour(index, offset) else {
        return true; // out of the box: the learner's box exit
    };
    let d = offset.len();
    let (mut from, mut to, mut z) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
    grid.point(index, &mut from);
    grid.point(next, &mut to);
    let mut q = vec![0.0; decoder.output_dim()];
    decoder.mean_into(&from, &mut q, scratch);
    if plant.reset(&q).is_some() {
        return true;
    }
    let mut reached = vec![0.0; q.len()];
    let steps = grid.stride();
    (1..=steps).any(|k| {
        let t = k as f64 / steps as f64;
        for ((z, a), b) in z.iter_mut().zip(&from).zip(&to) {
            *z = a + t * (b - a);
        }
        decoder.mean_into(&z, &mut q, scratch);
        plant.step(&q, &mut reached).end.is_some_and(|e| e.is_terminal())
    })
}

/// Breadth-first from the reached points backwards along every move: the fewest grid moves
/// (× the grid's stride) from each admissible point to a reached one; `blocked` (point-major,
/// one per move; empty: none) leaves moves out.
fn fewest_moves(
    grid: &LatentGrid,
    codes: &[u8],
    reached: &[bool],
    offsets: &[Vec<i64>],
    blocked: &[bool],
) -> Vec<Option<usize>> {
    let mut out = vec![None; grid.len()];
    let mut queue = VecDeque::new();
    for (i, _) in reached.iter().enumerate().filter(|(_, r)| **r) {
        out[i] = Some(0);
        queue.push_back(i);
    }
    let back: Vec<Vec<i64>> = offsets.iter().map(|o| o.iter().map(|x| -x).collect()).collect();
    let n_moves = offsets.len();
    while let Some(t) = queue.pop_front() {
        let next = out[t].map_or(0, |m| m + grid.stride());
        for (a, o) in back.iter().enumerate() {
            if let Some(p) = grid.neighbour(t, o)
                && codes[p] == 0
                && out[p].is_none()
                && !blocked.get(p * n_moves + a).copied().unwrap_or(false)
            {
                out[p] = Some(next);
                queue.push_back(p);
            }
        }
    }
    out
}

/// One chunk's per-point results, in point order.
#[derive(Default)]
struct Part {
    blocked: Vec<bool>,
    codes: Vec<u8>,
    reward: Vec<f64>,
    distance: Vec<f64>,
    reached: Vec<bool>,
    effectors: Vec<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_at_the_step_and_its_neighbours() {
        let g = LatentGrid::at_step(&[0.0, -1.0], &[1.0, 1.0], &[0.25, 0.5], 100);
        assert_eq!((g.shape(), g.stride(), g.len()), (&[5, 5][..], 1, 25));
        let mut p = [0.0; 2];
        g.point(7, &mut p);
        assert_eq!(p, [0.25, 0.0]);
        assert_eq!(g.neighbour(7, &[1, -1]), Some(11));
        assert_eq!(g.neighbour(7, &[0, -3]), None);
        // Coarsened to keep at most 10 points: two steps apart, 3 × 3.
        let coarse = LatentGrid::at_step(&[0.0, -1.0], &[1.0, 1.0], &[0.25, 0.5], 10);
        assert_eq!((coarse.shape(), coarse.stride()), (&[3, 3][..], 2));
    }

    #[test]
    fn a_cell_holds_the_points_a_learner_step_apart_around_its_point() {
        // Stride 2 (a 3 × 3 grid over [0, 1] × [-1, 1] at steps 0.25, 0.5): offsets −1 and 0.
        let coarse = LatentGrid::at_step(&[0.0, -1.0], &[1.0, 1.0], &[0.25, 0.5], 10);
        assert_eq!(coarse.cell(4), vec![0.25, -0.5, 0.25, 0.0, 0.5, -0.5, 0.5, 0.0]);
        // At the low corner only the points inside the grid's span.
        assert_eq!(coarse.cell(0), vec![0.0, -1.0]);
        assert_eq!(coarse.nearest(&[0.7, 0.4]), 4);
        assert_eq!(coarse.nearest(&[-5.0, 9.0]), 2);
        // Stride 3 along one axis: −1, 0, +1 steps.
        let line = LatentGrid::at_step(&[0.0], &[6.0], &[1.0], 3);
        assert_eq!((line.stride(), line.cell(1)), (3, vec![2.0, 3.0, 4.0]));
    }

    #[test]
    fn a_survey_by_name_pads_no_path_with_minus_one() {
        let grid = LatentGrid::at_step(&[0.0], &[1.0], &[0.5], 100);
        let survey = Survey {
            grid,
            codes: vec![0, 1, 0],
            reward: vec![-1.0, -2.0, 0.0],
            distance: vec![0.2, 0.3, 0.01],
            reached: vec![false, false, true],
            effectors: vec![0.0; 9],
            moves_to_target: vec![None, None, Some(0)],
            blocked: Vec::new(),
            moves_in_physics: Vec::new(),
            region_points: 1,
            closest: None,
        };
        let arrays = survey.arrays();
        let get = |name: &str| arrays.iter().find(|(n, _)| n == name).map(|(_, a)| a.clone());
        assert_eq!(get("points"), Some(ResultArray::F64(vec![0.0, 0.5, 1.0], vec![3, 1])));
        assert_eq!(get("moves"), Some(ResultArray::I64(vec![-1, -1, 0], vec![3])));
        assert_eq!(get("effectors"), Some(ResultArray::F64(vec![0.0; 9], vec![3, 3])));
        assert_eq!(get("moves_in_physics"), Some(ResultArray::I64(Vec::new(), vec![0])));
        let summary = survey.summary();
        assert_eq!(
            (summary.shape, summary.stride, summary.spacing),
            (vec![3], 1, vec![0.5])
        );
    }

    #[test]
    fn fewest_moves_go_around_what_is_not_admissible() {
        // 5 × 1 line... as a 1 × 5 grid: target at the right end, a wall at index 2.
        let g = LatentGrid::at_step(&[0.0], &[4.0], &[1.0], 100);
        let codes = [0, 0, 1, 0, 0];
        let reached = [false, false, false, false, true];
        let m = fewest_moves(&g, &codes, &reached, &[vec![1], vec![-1]], &[]);
        assert_eq!(m, [None, None, None, Some(1), Some(0)]);
        let open = fewest_moves(&g, &[0; 5], &reached, &[vec![1], vec![-1]], &[]);
        assert_eq!(open, [Some(4), Some(3), Some(2), Some(1), Some(0)]);
        // A one-way action set: only moves to the left; the target is out of reach.
        let left = fewest_moves(&g, &[0; 5], &reached, &[vec![-1]], &[]);
        assert_eq!(left, [None, None, None, None, Some(0)]);
        // The move right from point 2 breaks a rule on the way: 0–2 must go around, and cannot.
        let blocked = [false, false, false, false, true, false, false, false, false, false];
        let through = fewest_moves(&g, &[0; 5], &reached, &[vec![1], vec![-1]], &blocked);
        assert_eq!(through, [None, None, None, Some(1), Some(0)]);
    }
}
