//! A robot at a configuration against an environment cloud; self-collision.

use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;

use super::attached::AttachedObject;
use super::geometry::{sample_padded, samples_at, LinkGeometry, LinkSamples};
use super::model::Robot;
use super::shadow::{RobotShadow, ShadowSamples};
use super::target::{check_padding, resolve, GraspTarget, TargetCollision};
use crate::bvh::{Aabb, BvhWorkspace};
use crate::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::math::Pose;
use crate::probability::{normal_quantile, Aggregation, CollisionState};
use crate::query::collide::{
    collide_with_workspace, element_surfaces_may_reach, mesh_sampling_spacing, prepare,
    CollisionRequest, CollisionResult, MeshSide, QueryModel, WarmStart,
};
use crate::query::exact::intersects;
use crate::query::exact_side::{collide_exact_cloud_padded, exact_side_may_reach};
use crate::Real;

/// Options of [`collide_robot`]: the per-link query's options and the robot's own.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotRequest {
    /// The query of each link against the cloud (its options as
    /// [`crate::query::collide()`] reads them).
    pub collide: CollisionRequest,
    /// How each link stands in its query (default [`MeshSide::Exact`]): its
    /// exact surface, the link's cached signed distance
    /// ([`LinkGeometry::distance`]) read by
    /// [`collide_exact_cloud`](crate::query::exact_side::collide_exact_cloud),
    /// nothing sampled or trained; or ([`MeshSide::Sampled`]) its mesh
    /// sampled into a cloud, collided by [`crate::query::collide()`].
    pub mesh_side: MeshSide,
    /// Sampling spacing of the link meshes (metres), with
    /// [`MeshSide::Sampled`] only; `None`: half the cloud's median spacing, as
    /// [`crate::query::collide_mesh_cloud`] does.
    pub mesh_spacing: Option<Real>,
    /// Skip links that cannot reach the cloud (default `true`), reading
    /// `P = 0` without a query. Exact links: the link's bounding box, moved
    /// into the cloud's frame, descends the cloud's hierarchy over its points
    /// (points model) or over its element hulls (elements model), and the
    /// points or element surfaces of the leaves within the noise's reach are
    /// tested against the box in the link's frame; when none is within
    /// reach, the exact-side query would read nothing (but single points
    /// farther than their noise's reach, each below `prune_epsilon / 2`, as
    /// the exact side's per-point probabilities leave them). No signed
    /// distance is evaluated. Sampled links, points model: the link's
    /// bounding box is beyond the noise's reach of every node of the cloud's
    /// hierarchy, so no pair of points is near by the query's near rule
    /// (an attached cloud object, whose points carry noise, has its box
    /// grown by its largest noise sigma times the same `k` first).
    /// Sampled links, elements model: no element surface of the link may
    /// reach one of the cloud through the hierarchies over both clouds'
    /// element hulls (the elements query's own first test). The broad phase
    /// changes the cost, not the answer (exact links: not by more than
    /// `prune_epsilon / 2` per link).
    pub broad_phase: bool,
    /// Check self-collision between non-adjacent links (default `true`).
    pub self_collision: bool,
    /// A safety margin (metres, finite and `>= 0`; default 0) added to every
    /// link's surface: each link is queried as its surface grown by it, its
    /// signed distance less the padding (exact links); a sampled link's
    /// samples move that far along their faces' outward normals (the faces'
    /// offsets, without the exact offset's rounded edges; sampled again for
    /// each query call, once for a batch or a motion). It is
    /// deterministic: the sensor noise is already in `P`, so a padding `d`
    /// shifts `P`'s curve by `d / sigma` standard deviations; keep it for
    /// model error (kinematic calibration, mesh simplification). Attached
    /// objects are not padded. Padding 0 is no padding, bit for bit.
    pub padding: Real,
    /// Per-link paddings (metres) by link name, overriding `padding` for the
    /// links they name.
    pub link_padding: Vec<(String, Real)>,
    /// An object about to be grasped, still in the scene (default `None`):
    /// every link (and attached object) not in its
    /// [`GraspTarget::allowed_links`] is queried against it as against the
    /// environment, its probability entering the link's and the robot's; the
    /// allowed links' contacts with it are reported apart
    /// ([`RobotCollisionResult::target`], [`LinkCollision::target`]).
    pub target: Option<GraspTarget>,
    /// Read the scan's shadow (default `None`): a link whose surface reaches
    /// into space behind the observed surfaces reads at least the stated
    /// prior's probability ([`RobotShadow`], [`LinkCollision::shadow`]).
    pub shadow: Option<RobotShadow>,
}

impl Default for RobotRequest {
    fn default() -> Self {
        Self {
            collide: CollisionRequest::default(),
            mesh_side: MeshSide::default(),
            mesh_spacing: None,
            broad_phase: true,
            self_collision: true,
            padding: 0.0,
            link_padding: Vec::new(),
            target: None,
            shadow: None,
        }
    }
}

impl RobotRequest {
    /// Checks every field's domain.
    ///
    /// # Errors
    /// As [`CollisionRequest::validate`]; a mesh spacing that is not finite
    /// and positive, or given with [`MeshSide::Exact`] (nothing is sampled);
    /// the `surface` aggregation with the points model and an exact side (it
    /// reads a trained surface around each point); a padding that is not
    /// finite and `>= 0`. Link names are checked against the robot by the
    /// queries.
    pub fn validate(&self) -> Result<()> {
        self.collide.validate()?;
        if let Some(shadow) = &self.shadow {
            shadow.validate()?;
        }
        check_padding(self.padding, "padding")?;
        for (name, d) in &self.link_padding {
            check_padding(*d, &format!("padding of link '{name}'"))?;
        }
        if let Some(s) = self.mesh_spacing {
            if !(s.is_finite() && s > 0.0) {
                return Err(Error::invalid(format!(
                    "mesh_spacing must be finite and > 0, got {s}"
                )));
            }
        }
        if self.mesh_side == MeshSide::Exact {
            if self.mesh_spacing.is_some() {
                return Err(Error::invalid(
                    "mesh_spacing samples the link meshes: it needs mesh_side 'sampled'",
                ));
            }
            if self.collide.model == QueryModel::Points
                && self.collide.aggregation == Aggregation::Surface
            {
                return Err(Error::invalid(
                    "aggregation 'surface' reads a trained surface around each point: \
                     not available with exact links (use mesh_side 'sampled', or 'max', \
                     'union' or 'independent')",
                ));
            }
        }
        Ok(())
    }
}

/// One link's part of a [`RobotCollisionResult`].
#[derive(Debug, Clone, PartialEq)]
pub struct LinkCollision {
    /// The link's index ([`Robot::link_names`]); for an attached object,
    /// `links().len() + k` with `k` its place in [`Robot::attached_objects`]
    /// ([`Robot::entry_name`] names either).
    pub link: usize,
    /// The link's collision probability (0 when the broad phase skipped it;
    /// NaN when a `decide_only` query had decided before reaching it).
    pub probability: Real,
    /// Its state.
    pub state: CollisionState,
    /// Whether the link was queried (it passed the broad phase).
    pub queried: bool,
    /// The full query result, when queried (side A is the link: its exact
    /// surface, no points, with [`MeshSide::Exact`]; its sample, in the link's
    /// frame, with [`MeshSide::Sampled`]; regions in the world frame).
    pub result: Option<CollisionResult>,
    /// With a grasp target ([`RobotRequest::target`]), the body's query
    /// against it (its `target` is `None`); `None` without a target, or when
    /// a `decide_only` query had decided before reaching the body. A body
    /// not allowed to touch the target has it in `probability` and `state`
    /// (the request's aggregation of the environment's and the target's);
    /// an allowed body's `probability` is the environment's alone.
    pub target: Option<Box<LinkCollision>>,
    /// With [`RobotRequest::shadow`], the body's shadow probability (the
    /// prior times the largest probability of a surface sample lying in the
    /// scan's shadow), already in `probability`; 0 without.
    pub shadow: Real,
}

/// Two links (or a link and an attached object) whose exact shapes intersect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SelfCollision {
    /// The first link's index.
    pub link_a: usize,
    /// The second link's index (`link_a < link_b`); an attached object's is
    /// `links().len() + k`, as in [`LinkCollision::link`].
    pub link_b: usize,
}

/// The counters of one robot query: everything in [`RobotStats`] but the
/// wall time, so that two runs of one query compare equal.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RobotCounters {
    /// Links with geometry, and attached objects.
    pub links_with_geometry: usize,
    /// Links queried against the cloud (the others were skipped by the broad
    /// phase, or left once the query was decided), plus, with a grasp target,
    /// those queried against it.
    pub links_queried: usize,
    /// Links left unqueried because an earlier link's probability had reached
    /// the collision threshold (`decide_only` only).
    pub links_after_decision: usize,
    /// Hierarchy nodes (or node pairs) visited by the broad phase.
    pub broad_phase_nodes: usize,
    /// Link pairs tested for self-collision.
    pub self_pairs_checked: usize,
    /// Node pairs visited by the per-link queries, summed (for exact links,
    /// the cloud's elements tested against the link's surface).
    pub node_pairs_visited: usize,
    /// Interior-point iterations of the per-link queries' classifiers, summed
    /// (0 for exact links: nothing is trained).
    pub solver_iterations: u64,
}

/// Counters and timings of one robot query. Equality compares the counters,
/// not the wall time.
#[derive(Debug, Clone, Default)]
pub struct RobotStats {
    /// The counters.
    pub counters: RobotCounters,
    /// Wall time (seconds).
    pub time_seconds: Real,
}

impl PartialEq for RobotStats {
    fn eq(&self, o: &Self) -> bool {
        self.counters == o.counters
    }
}

/// The answer of [`collide_robot`].
#[derive(Debug, Clone, PartialEq)]
pub struct RobotCollisionResult {
    /// The robot's collision probability with the environment: the links'
    /// probabilities aggregated as the request's aggregation does points (the
    /// largest for `max` and `surface`, their capped sum for `union`,
    /// `1 - prod(1 - p)` for `independent`).
    pub probability: Real,
    /// The state from `probability` and the thresholds.
    pub state: CollisionState,
    /// One entry per link with geometry, in link order, then one per
    /// attached object, in [`Robot::attached_objects`] order.
    pub links: Vec<LinkCollision>,
    /// Pairs of non-adjacent links that intersect (exact meshes), empty when
    /// not requested. Reported apart: it does not enter `probability`.
    pub self_collisions: Vec<SelfCollision>,
    /// With a grasp target ([`RobotRequest::target`]): the allowed links'
    /// contact with it, reported apart, and the other links' collision with
    /// it (in `probability`).
    pub target: Option<TargetCollision>,
    /// Counters and timings.
    pub stats: RobotStats,
}

impl RobotCollisionResult {
    /// Whether self-collision was found.
    pub fn self_colliding(&self) -> bool {
        !self.self_collisions.is_empty()
    }
}

/// The spacing links are sampled at against `cloud`.
pub(crate) fn link_spacing(request: &RobotRequest, cloud: &PointCloud) -> Result<Real> {
    let s = match request.mesh_spacing {
        Some(s) => s,
        None => mesh_sampling_spacing(cloud),
    };
    if s > 0.0 && s.is_finite() {
        Ok(s)
    } else {
        Err(Error::invalid(
            "the cloud's points coincide (sampling spacing 0): give mesh_spacing",
        ))
    }
}

/// Whether any node of the cloud's hierarchy lies within the near rule's
/// reach of the box: `0.5 max(h_link, h_node) + sigma_node k`, with `k =
/// -Phi^-1(epsilon / 2)` (the link's samples carry no sensor noise). Counts
/// visited nodes.
fn near_cloud(
    link_box: &Aabb,
    h_link: Real,
    cloud: &PointCloud,
    k: Real,
    visited: &mut usize,
    stack: &mut Vec<u32>,
) -> bool {
    let nodes = cloud.bvh().nodes();
    let spacing = cloud.node_spacing();
    stack.clear();
    stack.push(0);
    while let Some(id) = stack.pop() {
        *visited += 1;
        let node = &nodes[id as usize];
        let reach = 0.5 * h_link.max(spacing[id as usize]) + node.sigma_max * k;
        if node.aabb.distance(link_box) > reach {
            continue;
        }
        match node.children {
            None => return true,
            Some([l, r]) => {
                stack.push(r);
                stack.push(l);
            }
        }
    }
    false
}

fn aggregate(aggregation: Aggregation, p: &[Real]) -> Real {
    match aggregation {
        Aggregation::Max | Aggregation::Surface => p.iter().copied().fold(0.0, Real::max),
        Aggregation::Union => p.iter().sum::<Real>().min(1.0),
        Aggregation::Independent => 1.0 - p.iter().map(|x| 1.0 - x).product::<Real>(),
    }
}

/// A link left unqueried by a decided `decide_only` query: its probability is
/// unknown (NaN), its state undecided.
fn after_decision(link: usize) -> LinkCollision {
    LinkCollision {
        link,
        probability: Real::NAN,
        state: CollisionState::Contact,
        queried: false,
        result: None,
        target: None,
        shadow: 0.0,
    }
}

/// Self-collision at the link poses `poses`: the checked link pairs whose
/// exact shapes intersect, then the attached objects' (see
/// [`Robot::attach`]).
pub(crate) fn self_collisions(robot: &Robot, poses: &[Pose]) -> Vec<SelfCollision> {
    let mut out: Vec<SelfCollision> = robot
        .self_pairs
        .iter()
        .filter_map(|&(a, b)| {
            let ga = robot.links[a].geometry.as_ref()?;
            let gb = robot.links[b].geometry.as_ref()?;
            intersects(&poses[a], &ga.exact, &poses[b], &gb.exact).then_some(SelfCollision {
                link_a: a,
                link_b: b,
            })
        })
        .collect();
    out.extend(robot.attached_self_collisions(poses));
    out
}

/// Workspace of one thread of robot queries.
#[derive(Debug, Default)]
pub(crate) struct RobotWorkspace {
    bvh: BvhWorkspace,
    stack: Vec<u32>,
    /// Per link, the classifier's hint from the last query of that link
    /// (`None`: every query starts cold; the batch queries, whose
    /// configurations need not be near each other, and whose answers must not
    /// depend on the order the threads take them in).
    warm: Option<Vec<WarmStart>>,
}

impl RobotWorkspace {
    /// A workspace whose queries carry each link's classifier hint to the next:
    /// for consecutive states of a motion.
    pub(crate) fn warm_started() -> Self {
        RobotWorkspace {
            warm: Some(Vec::new()),
            ..RobotWorkspace::default()
        }
    }
}

/// What stands for the links in a query.
#[derive(Debug)]
enum SideKind {
    /// Their exact surfaces ([`LinkGeometry::distance`]).
    Exact,
    /// Their samples at one spacing.
    Sampled(Arc<LinkSamples>),
}

/// What stands for the bodies in a query, with the request's padding and
/// grasp target resolved against the robot.
#[derive(Debug)]
pub(crate) struct LinkSides {
    kind: SideKind,
    /// Per entry (links, then attached objects): its padding (metres).
    padding: Vec<Real>,
    /// The grasp target's cloud and, per entry, whether it may touch it.
    target: Option<(Arc<PointCloud>, Vec<bool>)>,
    /// Sampled links only, per link with a positive padding: its padded
    /// sample.
    padded: Vec<Option<PaddedSample>>,
    /// With [`RobotRequest::shadow`], every entry's surface samples.
    shadow: Option<ShadowSamples>,
}

/// A sampled link's sample moved along its faces' normals by its padding.
#[derive(Debug)]
struct PaddedSample {
    cloud: PointCloud,
    /// The link's bounding box grown by the padding.
    aabb: Aabb,
    spacing_max: Real,
}

impl LinkSides {
    /// The sides `request` asks for against `cloud` (samples cached on the
    /// robot), its padding and target resolved.
    ///
    /// # Errors
    /// A cloud whose points coincide, with sampled links or a mesh target
    /// and no `mesh_spacing`; a link that cannot be sampled; a padding or
    /// allowed link naming nothing of the robot; a mesh target that cannot
    /// be sampled.
    pub(crate) fn new(robot: &Robot, request: &RobotRequest, cloud: &PointCloud) -> Result<Self> {
        let kind = match request.mesh_side {
            MeshSide::Exact => SideKind::Exact,
            MeshSide::Sampled => {
                SideKind::Sampled(samples_at(robot, link_spacing(request, cloud)?)?)
            }
        };
        let resolved = resolve(
            robot,
            (request.padding, &request.link_padding),
            request.target.as_ref(),
            || link_spacing(request, cloud),
        )?;
        let mut padded: Vec<Option<PaddedSample>> = Vec::new();
        if matches!(kind, SideKind::Sampled(_)) {
            let spacing = link_spacing(request, cloud)?;
            for (link, &d) in robot.links.iter().zip(&resolved.padding) {
                let sample = match &link.geometry {
                    Some(g) if d > 0.0 => {
                        let what = format!("link '{}'", link.name);
                        let (cloud, spacing_max) = sample_padded(g, spacing, d, &what)?;
                        let _ = cloud.bvh();
                        Some(PaddedSample {
                            cloud,
                            aabb: grown(&g.aabb, d),
                            spacing_max,
                        })
                    }
                    _ => None,
                };
                padded.push(sample);
            }
        }
        let shadow = match &request.shadow {
            Some(s) => Some(ShadowSamples::new(robot, s)?),
            None => None,
        };
        if matches!(kind, SideKind::Exact) {
            build_fields(robot);
        }
        Ok(LinkSides {
            kind,
            padding: resolved.padding,
            target: resolved.target,
            padded,
            shadow,
        })
    }

    /// Builds what every query of the sides against `cloud` (and the grasp
    /// target) reads, so that parallel queries do not race to build it.
    pub(crate) fn prepare(&self, cloud: &PointCloud, request: &CollisionRequest) {
        self.prepare_cloud(cloud, request);
        if let Some((target, _)) = &self.target {
            self.prepare_cloud(target, request);
        }
    }

    fn prepare_cloud(&self, cloud: &PointCloud, request: &CollisionRequest) {
        prepare(cloud, request);
        match &self.kind {
            SideKind::Exact => {
                for s in 0..request.segmentations {
                    let _ = cloud.segmentation_after(s).hulls();
                }
            }
            SideKind::Sampled(samples) => {
                for link_cloud in samples.clouds.iter().flatten() {
                    prepare(link_cloud, request);
                }
                for p in self.padded.iter().flatten() {
                    prepare(&p.cloud, request);
                }
                for (object_cloud, _) in samples.attached.iter().flatten() {
                    prepare(object_cloud, request);
                }
            }
        }
    }

    /// What stands for link `l` (with geometry `g`) in a query.
    fn link_body<'a>(&'a self, l: usize, g: &'a LinkGeometry) -> Body<'a> {
        if let Some(Some(p)) = self.padded.get(l) {
            return Body::Cloud {
                cloud: &p.cloud,
                aabb: &p.aabb,
                spacing_max: p.spacing_max,
                sigma_max: 0.0,
            };
        }
        match &self.kind {
            SideKind::Exact => Body::Exact(g, self.padding[l]),
            SideKind::Sampled(samples) => match &samples.clouds[l] {
                Some(cloud) => Body::Cloud {
                    cloud,
                    aabb: &g.aabb,
                    spacing_max: samples.spacing_max[l],
                    sigma_max: 0.0,
                },
                // Never: every link with geometry has a sample.
                None => Body::Exact(g, 0.0),
            },
        }
    }

    /// What stands for the attached object `k` in a query: a cloud object's
    /// cloud; a mesh object's exact surface or sample, as a link's.
    fn object_body<'a>(&'a self, k: usize, object: &'a AttachedObject) -> Body<'a> {
        let g = &object.geometry;
        if let Some(cloud) = &object.cloud {
            let (spacing_max, sigma_max) = object.cloud_spread;
            return Body::Cloud {
                cloud,
                aabb: &g.aabb,
                spacing_max,
                sigma_max,
            };
        }
        match &self.kind {
            SideKind::Exact => Body::Exact(g, 0.0),
            SideKind::Sampled(samples) => match &samples.attached[k] {
                Some((cloud, spacing_max)) => Body::Cloud {
                    cloud,
                    aabb: &g.aabb,
                    spacing_max: *spacing_max,
                    sigma_max: 0.0,
                },
                None => Body::Exact(g, 0.0),
            },
        }
    }
}

/// Builds the distance field of every exact body of `robot` not built yet
/// ([`LinkGeometry::field`]), in parallel: before the first query, so that no
/// query pays for one.
fn build_fields(robot: &Robot) {
    let bodies: Vec<&LinkGeometry> = robot
        .links
        .iter()
        .filter_map(|l| l.geometry.as_ref())
        .chain(
            robot
                .attached
                .iter()
                .filter(|o| o.cloud.is_none())
                .map(|o| &o.geometry),
        )
        .filter(|g| !g.has_field())
        .collect();
    // After the first query none is left: no work on the thread pool.
    if !bodies.is_empty() {
        bodies.par_iter().for_each(|g| {
            let _ = g.field();
        });
    }
}

/// What stands for one body of the robot (a link, or an attached object) in
/// its query against the environment, in the body's frame.
#[derive(Debug, Clone, Copy)]
enum Body<'a> {
    /// Its exact surface ([`LinkGeometry::distance`]), grown by a padding
    /// (metres).
    Exact(&'a LinkGeometry, Real),
    /// A cloud: a link's or mesh object's sample, or a cloud object's own.
    Cloud {
        /// The cloud.
        cloud: &'a PointCloud,
        /// The body's bounding box.
        aabb: &'a Aabb,
        /// The cloud's largest sampling spacing.
        spacing_max: Real,
        /// The largest noise standard deviation of its points (0 for a
        /// sample: it carries no sensor noise).
        sigma_max: Real,
    },
}

/// One robot query's fixed inputs.
struct Scene<'a> {
    cloud: &'a PointCloud,
    request: &'a RobotRequest,
    /// The noise's reach in standard deviations (`-Phi^-1(epsilon / 2)`).
    reach: Real,
    /// Added to a body's entry index for its classifier hint: the queries
    /// against the environment and against a grasp target keep apart hints.
    warm_offset: usize,
}

/// [`collide_robot`] with prepared link sides and a workspace; `q` checked.
pub(crate) fn collide_robot_prepared(
    robot: &Robot,
    sides: &LinkSides,
    q: &[Real],
    base: &Pose,
    cloud: &PointCloud,
    request: &RobotRequest,
    ws: &mut RobotWorkspace,
) -> RobotCollisionResult {
    let start = Instant::now();
    let poses = robot.link_poses_unchecked(q, base);
    let reach = -normal_quantile(0.5 * request.collide.prune_epsilon);
    let scene = Scene {
        cloud,
        request,
        reach,
        warm_offset: 0,
    };
    let entries = robot.links.len() + robot.attached.len();
    let target = sides.target.as_ref().map(|(target, allowed)| {
        (
            Scene {
                cloud: target,
                request,
                reach,
                warm_offset: entries,
            },
            allowed,
        )
    });
    let aggregation = request.collide.aggregation;
    let mut stats = RobotStats::default();
    let mut links = Vec::new();
    // Every aggregation is at least the largest link probability: once a link
    // reaches the collision threshold, a decide_only query is decided.
    let mut decided = false;
    let object_poses = robot.attached_poses_from(&poses);
    let link_bodies = robot.links.iter().enumerate().filter_map(|(l, link)| {
        let g = link.geometry.as_ref()?;
        Some((l, sides.link_body(l, g), &poses[l]))
    });
    let object_bodies = robot.attached.iter().enumerate().map(|(k, object)| {
        (
            robot.links.len() + k,
            sides.object_body(k, object),
            &object_poses[k],
        )
    });
    for (l, body, pose) in link_bodies.chain(object_bodies) {
        stats.counters.links_with_geometry += 1;
        if decided {
            stats.counters.links_after_decision += 1;
            links.push(after_decision(l));
            continue;
        }
        let mut entry = query_link(&scene, (l, body, pose), ws, &mut stats.counters);
        if let Some((target_scene, allowed)) = &target {
            let t = query_link(target_scene, (l, body, pose), ws, &mut stats.counters);
            if !allowed[l] {
                entry.probability = aggregate(aggregation, &[entry.probability, t.probability]);
                entry.state = request.collide.thresholds.state(entry.probability);
            }
            entry.target = Some(Box::new(t));
        }
        if let Some(shadow) = &sides.shadow {
            entry.shadow = shadow.probability(l, pose);
            if entry.shadow > 0.0 {
                entry.probability = aggregate(aggregation, &[entry.probability, entry.shadow]);
                entry.state = request.collide.thresholds.state(entry.probability);
            }
        }
        decided = request.collide.decide_only
            && entry.queried
            && entry.probability >= request.collide.thresholds.collision;
        links.push(entry);
    }
    let p: Vec<Real> = links
        .iter()
        .map(|l| l.probability)
        .filter(|p| !p.is_nan())
        .collect();
    let probability = aggregate(aggregation, &p);
    let target = target.map(|(_, allowed)| target_collision(request, &links, allowed));
    let self_collisions = if request.self_collision {
        stats.counters.self_pairs_checked = robot.self_pairs.len() + robot.attached_pairs();
        self_collisions(robot, &poses)
    } else {
        Vec::new()
    };
    stats.time_seconds = start.elapsed().as_secs_f64();
    RobotCollisionResult {
        probability,
        state: request.collide.thresholds.state(probability),
        links,
        self_collisions,
        target,
        stats,
    }
}

/// The grasp target's summary: the allowed bodies' contact with it, the
/// others' collision with it, each aggregated as the robot's probability.
fn target_collision(
    request: &RobotRequest,
    links: &[LinkCollision],
    allowed: &[bool],
) -> TargetCollision {
    let (mut touch, mut other) = (Vec::new(), Vec::new());
    for l in links {
        if let Some(t) = &l.target {
            if !t.probability.is_nan() {
                if allowed[l.link] {
                    &mut touch
                } else {
                    &mut other
                }
                .push(t.probability);
            }
        }
    }
    let aggregation = request.collide.aggregation;
    let probability = aggregate(aggregation, &touch);
    TargetCollision {
        probability,
        state: request.collide.thresholds.state(probability),
        other_probability: aggregate(aggregation, &other),
    }
}

/// One body (its entry index, what stands for it and its world pose) against
/// the cloud: skipped by the broad phase, or queried.
fn query_link(
    scene: &Scene<'_>,
    (l, body, pose): (usize, Body<'_>, &Pose),
    ws: &mut RobotWorkspace,
    counters: &mut RobotCounters,
) -> LinkCollision {
    let request = scene.request;
    if request.broad_phase && !link_near(scene, body, pose, ws, counters) {
        return LinkCollision {
            link: l,
            probability: 0.0,
            state: request.collide.thresholds.state(0.0),
            queried: false,
            result: None,
            target: None,
            shadow: 0.0,
        };
    }
    counters.links_queried += 1;
    match link_query(scene, (l, body, pose), ws) {
        Ok(r) => {
            counters.node_pairs_visited += r.stats.counters.node_pairs_visited;
            counters.solver_iterations += r.stats.counters.solver_iterations;
            LinkCollision {
                link: l,
                probability: r.probability,
                state: r.state,
                queried: true,
                result: Some(r),
                target: None,
                shadow: 0.0,
            }
        }
        // The request was validated by the caller; a query error cannot occur.
        Err(_) => LinkCollision {
            link: l,
            probability: 1.0,
            state: CollisionState::Collision,
            queried: true,
            result: None,
            target: None,
            shadow: 0.0,
        },
    }
}

/// Whether the link may reach the cloud (the broad phase, see
/// [`RobotRequest::broad_phase`]); counts the visited nodes.
fn link_near(
    scene: &Scene<'_>,
    body: Body<'_>,
    pose: &Pose,
    ws: &mut RobotWorkspace,
    counters: &mut RobotCounters,
) -> bool {
    let (cloud, collide) = (scene.cloud, &scene.request.collide);
    let (link_cloud, aabb, spacing_max, sigma_max) = match body {
        Body::Exact(geometry, padding) => {
            let (near, visited) = exact_side_may_reach(
                (&grown(&geometry.aabb, padding), pose),
                cloud,
                (collide, scene.reach),
                &mut ws.stack,
            );
            counters.broad_phase_nodes += visited;
            return near;
        }
        Body::Cloud {
            cloud,
            aabb,
            spacing_max,
            sigma_max,
        } => (cloud, aabb, spacing_max, sigma_max),
    };
    match collide.model {
        // The elements model's own first test: the hierarchies over both
        // clouds' element hulls (the query reads P = 0 when it fails). With
        // several segmentations, any of them that may reach.
        QueryModel::Elements => (0..collide.segmentations).any(|s| {
            let (may, visited) = element_surfaces_may_reach(
                link_cloud.segmentation_after(s),
                pose,
                cloud.segmentation_after(s),
                scene.reach,
                &mut ws.bvh,
            );
            counters.broad_phase_nodes += visited;
            may
        }),
        // A noisy body's box (a cloud object's) grown by its own noise's reach.
        QueryModel::Points => near_cloud(
            &grown(&aabb.transformed(pose), sigma_max * scene.reach),
            spacing_max,
            cloud,
            scene.reach,
            &mut counters.broad_phase_nodes,
            &mut ws.stack,
        ),
    }
}

/// `b` grown by `d` on every side.
fn grown(b: &Aabb, d: Real) -> Aabb {
    let mut out = *b;
    for a in 0..3 {
        out.mins[a] -= d;
        out.maxs[a] += d;
    }
    out
}

/// The query of one body that passed the broad phase.
fn link_query(
    scene: &Scene<'_>,
    (l, body, pose): (usize, Body<'_>, &Pose),
    ws: &mut RobotWorkspace,
) -> Result<CollisionResult> {
    let (cloud, collide) = (scene.cloud, &scene.request.collide);
    let link_cloud = match body {
        Body::Exact(geometry, padding) => {
            return collide_exact_cloud_padded(
                pose,
                (&geometry.distance, padding, geometry.field()),
                &Pose::identity(),
                cloud,
                collide,
            )
        }
        Body::Cloud { cloud, .. } => cloud,
    };
    let slot = l + scene.warm_offset;
    let warm = ws.warm.as_mut().map(|w| {
        if w.len() <= slot {
            w.resize_with(slot + 1, WarmStart::default);
        }
        &mut w[slot]
    });
    collide_with_workspace(
        pose,
        link_cloud,
        &Pose::identity(),
        cloud,
        collide,
        &mut ws.bvh,
        warm,
    )
}

/// The robot at configuration `q`, its root link at `base`, against the
/// environment cloud `cloud` (world frame).
///
/// Each link with geometry stands, by default ([`MeshSide::Exact`]), as its
/// exact surface: its signed distance, built when the robot was loaded
/// ([`LinkGeometry::distance`]), queried by
/// [`collide_exact_cloud`](crate::query::exact_side::collide_exact_cloud) at
/// its pose. With [`MeshSide::Sampled`] it stands as the cloud sampled from
/// its mesh (no sensor noise, its own discretization covariance; sampled once
/// per spacing and cached on the robot), queried by
/// [`crate::query::collide()`]. A broad phase first skips the links beyond
/// the noise's reach of the cloud (see [`RobotRequest::broad_phase`]).
/// Self-collision between non-adjacent links is checked on the exact meshes
/// and reported apart.
///
/// # Errors
/// As [`Robot::check_configuration`] for `q`; an invalid request; a
/// non-finite `base`.
pub fn collide_robot(
    robot: &Robot,
    q: &[Real],
    base: &Pose,
    cloud: &PointCloud,
    request: &RobotRequest,
) -> Result<RobotCollisionResult> {
    request.validate()?;
    robot.check_configuration(q)?;
    check_base(base)?;
    let sides = LinkSides::new(robot, request, cloud)?;
    let mut ws = RobotWorkspace::default();
    Ok(collide_robot_prepared(
        robot, &sides, q, base, cloud, request, &mut ws,
    ))
}

/// [`collide_robot`] for each configuration of `qs`, in parallel (rayon);
/// results in the order of `qs`. Every configuration is checked before any
/// query runs.
///
/// # Errors
/// As [`collide_robot`], naming the configuration's index.
pub fn collide_robot_many(
    robot: &Robot,
    qs: &[Vec<Real>],
    base: &Pose,
    cloud: &PointCloud,
    request: &RobotRequest,
) -> Result<Vec<RobotCollisionResult>> {
    request.validate()?;
    check_base(base)?;
    for (i, q) in qs.iter().enumerate() {
        robot.check_configuration(q).map_err(|e| match e {
            Error::InvalidInput(m) => Error::InvalidInput(format!("configuration {i}: {m}")),
            Error::Shape {
                what,
                expected,
                got,
            } => Error::Shape {
                what: format!("configuration {i}: {what}"),
                expected,
                got,
            },
            other => other,
        })?;
    }
    let sides = LinkSides::new(robot, request, cloud)?;
    sides.prepare(cloud, &request.collide);
    Ok(qs
        .par_iter()
        .map_init(RobotWorkspace::default, |ws, q| {
            collide_robot_prepared(robot, &sides, q, base, cloud, request, ws)
        })
        .collect())
}

pub(crate) fn check_base(base: &Pose) -> Result<()> {
    let finite = base.translation.vector.iter().all(|v| v.is_finite())
        && base.rotation.coords.iter().all(|v| v.is_finite());
    if finite {
        Ok(())
    } else {
        Err(Error::invalid("base pose has a non-finite entry"))
    }
}

impl Robot {
    /// Pairs of non-adjacent links whose exact shapes intersect at
    /// configuration `q` (see [`Robot::self_collision_pairs`]), then attached
    /// objects that intersect a link other than their holder and touch links
    /// (see [`Robot::attach`]).
    ///
    /// # Errors
    /// As [`Robot::check_configuration`].
    pub fn self_collisions(&self, q: &[Real]) -> Result<Vec<SelfCollision>> {
        let poses = self.link_poses(q, &Pose::identity())?;
        Ok(self_collisions(self, &poses))
    }

    /// The self-filter of the robot at `q` (root at `base`, in the cloud's
    /// frame): every link with geometry, its merged collision mesh at its
    /// pose, then every attached object (a mesh object's mesh, a cloud
    /// object's convex hull) at its pose: the camera sees the held object too.
    ///
    /// # Errors
    /// As [`Robot::check_configuration`] and [`crate::filter::SelfFilter::new`];
    /// a robot without geometry.
    pub fn self_filter(
        &self,
        q: &[Real],
        base: &Pose,
        padding: Real,
    ) -> Result<crate::filter::SelfFilter> {
        check_base(base)?;
        let poses = self.link_poses(q, base)?;
        let object_poses = self.attached_poses_from(&poses);
        let links: Vec<_> = self
            .links
            .iter()
            .zip(&poses)
            .filter_map(|(l, p)| l.geometry.as_ref().map(|g| (g.mesh.clone(), *p)))
            .chain(
                self.attached
                    .iter()
                    .zip(&object_poses)
                    .map(|(o, p)| (o.geometry.mesh.clone(), *p)),
            )
            .collect();
        if links.is_empty() {
            return Err(Error::invalid(format!(
                "robot '{}' has no collision geometry",
                self.name
            )));
        }
        crate::filter::SelfFilter::new(links, padding)
    }
}
