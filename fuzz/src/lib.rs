//! The bodies of cloudprox's fuzz targets, one public function per target.
//!
//! Each takes the fuzzer's bytes and must return without a panic, a hang or an
//! unbounded allocation, whatever the bytes are: errors are the expected
//! outcome of bad input. The readers get the bytes as a file; `pointcloud2`,
//! `collide` and `exact` build a structured input from them with `arbitrary`.
//!
//! The cargo-fuzz targets (`fuzz/fuzz_targets/*.rs`, nightly) call these
//! functions; so does the stable smoke test `crates/cloudprox/tests/fuzz_smoke.rs`
//! (which includes this file as a module), over seeds and mutated inputs.

use std::alloc::{GlobalAlloc, Layout, System};

use arbitrary::{Arbitrary, Unstructured};

use cloudprox::classify::{ClassifySettings, SocpSolver, Surface};
use cloudprox::cloud::{pose_from_matrix, PointCloud};
use cloudprox::io::{
    las, npy, obj, off, pcd, ply, pointcloud2, stl, xyz, CloudData, Encoding, MeshData,
};
use cloudprox::math::{Matrix3, Matrix4, Point3, Pose, Vector3};
use cloudprox::probability::{Aggregation, Thresholds};
use cloudprox::query::collide::{
    collide as collide_query, collide_mesh_cloud, mesh_sampling_spacing, CollisionRequest,
    MeshSampling, QueryModel,
};
use cloudprox::query::exact::{exact_intersects, exact_proximity, ExactShape};
use cloudprox::robot::Robot;
use cloudprox::shape::Mesh;
use cloudprox::uncertainty::RobustModel;

/// The largest single allocation a target may make (512 MiB): the inputs are
/// at most 1 MiB, so anything near this is a size taken from a header without
/// checking it against the data. Larger requests abort (a crash to libFuzzer,
/// a failed test to the smoke test), whatever the sanitizer.
pub const MAX_ALLOCATION: usize = 512 << 20;

/// The system allocator, with [`MAX_ALLOCATION`] enforced.
pub struct CappedAllocator;

// SAFETY: every call is forwarded unchanged to the system allocator; the only
// addition is an abort before an oversized request.
unsafe impl GlobalAlloc for CappedAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        check_size(layout.size());
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        check_size(layout.size());
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        check_size(new_size);
        // SAFETY: forwarded with the caller's guarantees.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

fn check_size(size: usize) {
    if size > MAX_ALLOCATION {
        // No formatting machinery here (it could allocate): a fixed message.
        let msg = b"cloudprox fuzz: an allocation above MAX_ALLOCATION (512 MiB)\n";
        let _ = std::io::Write::write_all(&mut std::io::stderr(), msg);
        std::process::abort();
    }
}

#[global_allocator]
static ALLOCATOR: CappedAllocator = CappedAllocator;

/// The names of the fuzz targets, in the order `scripts/fuzz.sh` runs them.
pub const TARGETS: [&str; 14] = [
    "ply",
    "pcd",
    "las",
    "stl",
    "obj",
    "off",
    "npy",
    "xyz",
    "pointcloud2",
    "pointcloud2_message",
    "urdf",
    "srdf",
    "collide",
    "exact",
];

/// Runs the body of the target named `name` on `data` (`false` for an unknown
/// name).
pub fn run(name: &str, data: &[u8]) -> bool {
    match name {
        "ply" => ply(data),
        "pcd" => pcd(data),
        "las" => las(data),
        "stl" => stl(data),
        "obj" => obj(data),
        "off" => off(data),
        "npy" => npy(data),
        "xyz" => xyz(data),
        "pointcloud2" => pointcloud2(data),
        "pointcloud2_message" => pointcloud2_message(data),
        "urdf" => urdf(data),
        "srdf" => srdf(data),
        "collide" => collide(data),
        "exact" => exact(data),
        _ => return false,
    }
    true
}

/// The structured input that target `name` builds from `data`, for a crash
/// report (`None` for the readers, whose input is the bytes themselves).
pub fn describe(name: &str, data: &[u8]) -> Option<String> {
    let u = Unstructured::new(data);
    Some(match name {
        "pointcloud2" => format!("{:#?}", Pc2Input::arbitrary_take_rest(u).ok()?),
        "collide" => {
            let input = CollideInput::arbitrary_take_rest(u).ok()?;
            let cloud = |c: &CloudInput| {
                c.build()
                    .map(|c| (c.points().to_vec(), c.covariances().to_vec()))
            };
            format!(
                "{input:#?}\na = {:?}\nb = {:?}\npose_a = {:?}\npose_b = {:?}\nrequest = {:#?}",
                cloud(&input.a),
                cloud(&input.b),
                input.pose_a.build(),
                input.pose_b.build(),
                input.request.build()
            )
        }
        "exact" => format!("{:#?}", ExactInput::arbitrary_take_rest(u).ok()?),
        _ => return None,
    })
}

const ENCODINGS: [Encoding; 4] = [
    Encoding::Ascii,
    Encoding::BinaryLittleEndian,
    Encoding::BinaryBigEndian,
    Encoding::BinaryCompressed,
];

/// An encoding picked by the data (so that every writer path is exercised).
fn encoding_of(data: &[u8]) -> Encoding {
    ENCODINGS[data.len() % ENCODINGS.len()]
}

/// A cloud read from fuzz data must also write (or fail cleanly) and read
/// back: one writer per input, picked by the data.
fn round_trip_cloud(cloud: &CloudData, data: &[u8]) {
    let enc = encoding_of(data);
    match data.len() % 5 {
        0 => {
            if let Ok(bytes) = ply::write_ply(cloud, enc) {
                let _ = ply::read_ply(&bytes, "roundtrip.ply");
            }
        }
        1 => {
            if let Ok(bytes) = pcd::write_pcd(cloud, enc) {
                let _ = pcd::read_pcd(&bytes, "roundtrip.pcd");
            }
        }
        2 => {
            if let Ok(bytes) = xyz::write_xyz(cloud, b',') {
                let _ = xyz::read_xyz(&bytes, "roundtrip.csv");
            }
        }
        3 => {
            if let Ok(bytes) = npy::write_npy(cloud) {
                let _ = npy::read_npy(&bytes, "roundtrip.npy");
            }
        }
        _ => {
            if let Ok((layout, bytes)) = pointcloud2::write_pointcloud2(cloud) {
                let _ = pointcloud2::read_pointcloud2(&layout, &bytes);
            }
        }
    }
}

/// A mesh read from fuzz data must also write: one mesh format per input.
fn round_trip_mesh(mesh: &MeshData, data: &[u8]) {
    let enc = encoding_of(data);
    let _ = match data.len() % 4 {
        0 => stl::write_stl_mesh(&mesh.mesh, enc),
        1 => obj::write_obj_mesh(&mesh.mesh),
        2 => off::write_off_mesh(&mesh.mesh),
        _ => ply::write_ply_mesh(&mesh.mesh, enc),
    };
}

/// PLY: as a point cloud and as a mesh.
pub fn ply(data: &[u8]) {
    if let Ok(cloud) = ply::read_ply(data, "fuzz.ply") {
        round_trip_cloud(&cloud, data);
    }
    if let Ok(mesh) = ply::read_ply_mesh(data, "fuzz.ply") {
        round_trip_mesh(&mesh, data);
    }
}

/// PCD (ascii, binary, binary_compressed).
pub fn pcd(data: &[u8]) {
    if let Ok(cloud) = pcd::read_pcd(data, "fuzz.pcd") {
        round_trip_cloud(&cloud, data);
    }
}

/// LAS and LAZ.
pub fn las(data: &[u8]) {
    if let Ok(cloud) = las::read_las(data, "fuzz.laz") {
        round_trip_cloud(&cloud, data);
    }
}

/// STL (ascii, binary).
pub fn stl(data: &[u8]) {
    if let Ok(mesh) = stl::read_stl_mesh(data, "fuzz.stl") {
        round_trip_mesh(&mesh, data);
    }
}

/// OBJ.
pub fn obj(data: &[u8]) {
    if let Ok(mesh) = obj::read_obj_mesh(data, "fuzz.obj") {
        round_trip_mesh(&mesh, data);
    }
}

/// OFF.
pub fn off(data: &[u8]) {
    if let Ok(mesh) = off::read_off_mesh(data, "fuzz.off") {
        round_trip_mesh(&mesh, data);
    }
}

/// NPY.
pub fn npy(data: &[u8]) {
    if let Ok(cloud) = npy::read_npy(data, "fuzz.npy") {
        round_trip_cloud(&cloud, data);
    }
}

/// XYZ and CSV (one reader).
pub fn xyz(data: &[u8]) {
    if let Ok(cloud) = xyz::read_xyz(data, "fuzz.xyz") {
        round_trip_cloud(&cloud, data);
    }
}

/// The field names a PointCloud2 layout is drawn from (the ones the reader
/// looks for, and one it ignores).
const PC2_NAMES: [&str; 8] = ["x", "y", "z", "normal_x", "normal_y", "normal_z", "rgb", ""];

#[derive(Debug, Arbitrary)]
struct Pc2Field {
    name: u8,
    offset: u32,
    datatype: u8,
    count: u32,
}

#[derive(Debug, Arbitrary)]
struct Pc2Input {
    height: u32,
    width: u32,
    fields: Vec<Pc2Field>,
    is_bigendian: bool,
    point_step: u32,
    row_step: u32,
    /// Small offsets, datatypes and counts (most layouts then make sense).
    tame: bool,
    data: Vec<u8>,
}

/// PointCloud2: an arbitrary layout (fields, steps, sizes) over arbitrary data.
pub fn pointcloud2(data: &[u8]) {
    let Ok(input) = Pc2Input::arbitrary_take_rest(Unstructured::new(data)) else {
        return;
    };
    let tame = |v: u32, m: u32| if input.tame { v % m } else { v };
    let layout = pointcloud2::PointCloud2Layout {
        height: tame(input.height, 8),
        width: tame(input.width, 64),
        fields: input
            .fields
            .iter()
            .take(16)
            .map(|f| pointcloud2::PointField {
                name: PC2_NAMES[usize::from(f.name) % PC2_NAMES.len()].to_string(),
                offset: tame(f.offset, 64),
                datatype: if input.tame {
                    f.datatype % 9
                } else {
                    f.datatype
                },
                count: tame(f.count, 3),
            })
            .collect(),
        is_bigendian: input.is_bigendian,
        point_step: tame(input.point_step, 80),
        row_step: tame(input.row_step, 4096),
    };
    if let Ok(cloud) = pointcloud2::read_pointcloud2(&layout, &input.data) {
        round_trip_cloud(&cloud, data);
    }
}

/// A serialized PointCloud2 message as a bag stores it: the first byte picks
/// the encoding (even: CDR, as rosbag2 stores it; odd: ROS 1), the rest is
/// the message, whose points are read straight from its bytes.
pub fn pointcloud2_message(data: &[u8]) {
    let Some((&pick, message)) = data.split_first() else {
        return;
    };
    let encoding = if pick % 2 == 0 {
        pointcloud2::MessageEncoding::Cdr
    } else {
        pointcloud2::MessageEncoding::Ros1
    };
    let name = "fuzz.db3 (topic /points, message 0)";
    if let Ok((cloud, _)) = pointcloud2::read_pointcloud2_message(message, encoding, name) {
        round_trip_cloud(&cloud, data);
    }
}

/// URDF text (mesh files are looked up nowhere but in an empty package list).
pub fn urdf(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = Robot::from_urdf_str(text, "fuzz.urdf", None, &[]);
}

/// SRDF text applied to the robot of [`URDF_SEED`]: an error or a robot
/// whose checked and ignored pairs are, together, the pairs they were.
pub fn srdf(data: &[u8]) {
    static SEED_ROBOT: std::sync::OnceLock<Robot> = std::sync::OnceLock::new();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let seed = SEED_ROBOT.get_or_init(|| {
        Robot::from_urdf_str(URDF_SEED, "seed.urdf", None, &[]).expect("the seed URDF loads")
    });
    let mut robot = seed.clone();
    if robot.apply_srdf_str(text, "fuzz.srdf").is_ok() {
        let pairs = |r: &Robot| {
            let mut all = [r.self_collision_pairs(), r.ignored_pairs()].concat();
            all.sort_unstable();
            all
        };
        assert_eq!(pairs(&robot), pairs(seed));
    } else {
        assert_eq!(robot.self_collision_pairs(), seed.self_collision_pairs());
    }
}

/// A number: mostly small decimals, sometimes any `f64` (NaN, infinities,
/// huge and subnormal values included).
#[derive(Debug, Clone, Copy, Arbitrary)]
enum Num {
    /// `k / 1000`.
    Milli(i16),
    /// `k / 1e6`.
    Micro(i16),
    /// Any bit pattern.
    Raw(f64),
    /// One of the special values.
    Special(u8),
}

impl Num {
    fn value(self) -> f64 {
        match self {
            Num::Milli(k) => f64::from(k) / 1000.0,
            Num::Micro(k) => f64::from(k) / 1e6,
            Num::Raw(x) => x,
            Num::Special(k) => [
                0.0,
                -0.0,
                f64::NAN,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::MIN_POSITIVE,
                f64::EPSILON,
                1e-300,
                1e300,
                f64::MAX,
                1.0,
                0.5,
                1.0 - f64::EPSILON,
            ][usize::from(k) % 13],
        }
    }
}

/// How a cloud's covariances are given.
#[derive(Debug, Arbitrary)]
enum NoiseInput {
    Isotropic(Num),
    PerPoint(Vec<Num>),
    /// Upper triangles `xx xy xz yy yz zz`.
    Full(Vec<[Num; 6]>),
    /// Full matrices, not necessarily symmetric.
    Raw(Vec<[Num; 9]>),
}

#[derive(Debug, Arbitrary)]
struct CloudInput {
    points: Vec<[Num; 3]>,
    noise: NoiseInput,
}

const MAX_POINTS: usize = 64;

impl CloudInput {
    /// The cloud, or `None` where cloudprox rejects it (which must be an error,
    /// not a panic).
    fn build(&self) -> Option<PointCloud> {
        let points: Vec<Point3> = self
            .points
            .iter()
            .take(MAX_POINTS)
            .map(|p| Point3::new(p[0].value(), p[1].value(), p[2].value()))
            .collect();
        let n = points.len();
        let cloud = match &self.noise {
            NoiseInput::Isotropic(s) => PointCloud::from_sigma(points, s.value()),
            NoiseInput::PerPoint(s) => {
                PointCloud::from_sigmas(points, s.iter().take(n + 1).map(|s| s.value()).collect())
            }
            NoiseInput::Full(c) => {
                let covs = c
                    .iter()
                    .take(n + 1)
                    .map(|c| {
                        let [xx, xy, xz, yy, yz, zz] = c.map(Num::value);
                        Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
                    })
                    .collect();
                PointCloud::from_covariances(points, covs)
            }
            NoiseInput::Raw(c) => {
                let covs = c
                    .iter()
                    .take(n + 1)
                    .map(|c| Matrix3::from_row_slice(&c.map(Num::value)))
                    .collect();
                PointCloud::from_covariances(points, covs)
            }
        };
        cloud.ok()
    }
}

/// A pose: translation and quaternion (normalized, possibly non-finite), or a
/// 4x4 matrix that must pass `pose_from_matrix`.
#[derive(Debug, Arbitrary)]
enum PoseInput {
    Identity,
    Parts([Num; 3], [Num; 4]),
    Matrix([Num; 16]),
}

impl PoseInput {
    fn build(&self) -> Option<Pose> {
        match self {
            PoseInput::Identity => Some(Pose::identity()),
            PoseInput::Parts(t, q) => {
                let [x, y, z] = t.map(Num::value);
                let [w, i, j, k] = q.map(Num::value);
                Some(Pose::from_parts(
                    nalgebra::Translation3::new(x, y, z),
                    nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(w, i, j, k)),
                ))
            }
            PoseInput::Matrix(m) => {
                pose_from_matrix(&Matrix4::from_row_slice(&m.map(Num::value))).ok()
            }
        }
    }
}

/// An option: the default or a fuzzed value.
#[derive(Debug, Clone, Copy, Arbitrary)]
enum Opt<T> {
    Default,
    Set(T),
}

impl<T: Copy> Opt<T> {
    fn apply(self, field: &mut T) {
        if let Opt::Set(v) = self {
            *field = v;
        }
    }
}

/// The options of a request, as flags and optional values.
#[allow(clippy::struct_excessive_bools)]
#[derive(Debug, Arbitrary)]
struct RequestInput {
    elements: bool,
    linear: bool,
    aggregation: u8,
    threshold_collision: Opt<Num>,
    threshold_free: Opt<Num>,
    prune_epsilon: Opt<Num>,
    near_context: Opt<Num>,
    region_max_points: Opt<u16>,
    use_hierarchy: bool,
    decide_only: bool,
    slack_weight: Opt<Num>,
    robust_eta: Opt<Num>,
    chebyshev: bool,
    clarabel: bool,
    solver_max_iter: Opt<u8>,
    solver_tol: Opt<Num>,
    /// Plus one, modulo 18: 1 (the default) when the input runs out; 0 and
    /// 17 are out of range.
    segmentations: u8,
}

impl RequestInput {
    /// The request as given (not validated: `collide` validates).
    fn build(&self) -> CollisionRequest {
        let mut r = CollisionRequest {
            model: if self.elements {
                QueryModel::Elements
            } else {
                QueryModel::Points
            },
            aggregation: [
                Aggregation::Max,
                Aggregation::Surface,
                Aggregation::Union,
                Aggregation::Independent,
            ][usize::from(self.aggregation) % 4],
            use_hierarchy: self.use_hierarchy,
            decide_only: self.decide_only,
            segmentations: (u32::from(self.segmentations) + 1) % 18,
            ..CollisionRequest::default()
        };
        let num = |o: Opt<Num>, field: &mut f64| {
            if let Opt::Set(v) = o {
                *field = v.value();
            }
        };
        let mut t = Thresholds::default();
        num(self.threshold_collision, &mut t.collision);
        num(self.threshold_free, &mut t.free);
        r.thresholds = t;
        num(self.prune_epsilon, &mut r.prune_epsilon);
        num(self.near_context, &mut r.near_context);
        if let Opt::Set(n) = self.region_max_points {
            r.region_max_points = usize::from(n);
        }
        let mut c = ClassifySettings {
            surface: if self.linear {
                Surface::Linear
            } else {
                Surface::Quadric
            },
            robust_model: if self.chebyshev {
                RobustModel::Chebyshev
            } else {
                RobustModel::Gaussian
            },
            solver: if self.clarabel {
                SocpSolver::Clarabel
            } else {
                SocpSolver::PrimalDual
            },
            ..ClassifySettings::default()
        };
        num(self.slack_weight, &mut c.slack_weight);
        num(self.robust_eta, &mut c.robust_eta);
        num(self.solver_tol, &mut c.solver_tol);
        let mut iters = 100u8;
        self.solver_max_iter.apply(&mut iters);
        c.solver_max_iter = u32::from(iters);
        r.classify = c;
        r
    }
}

#[derive(Debug, Arbitrary)]
struct CollideInput {
    a: CloudInput,
    b: CloudInput,
    pose_a: PoseInput,
    pose_b: PoseInput,
    request: RequestInput,
}

/// `collide` on two small clouds (0 to 64 points, any coordinates and
/// covariances), any poses and options. Also checks what the result promises:
/// `P` in `[0, 1]` and one probability per point.
pub fn collide(data: &[u8]) {
    let Ok(input) = CollideInput::arbitrary_take_rest(Unstructured::new(data)) else {
        return;
    };
    let (Some(a), Some(b)) = (input.a.build(), input.b.build()) else {
        return;
    };
    let (Some(pose_a), Some(pose_b)) = (input.pose_a.build(), input.pose_b.build()) else {
        return;
    };
    let request = input.request.build();
    if let Ok(result) = collide_query(&pose_a, &a, &pose_b, &b, &request) {
        assert!(
            (0.0..=1.0).contains(&result.probability),
            "P = {} outside [0, 1]",
            result.probability
        );
        if !request.decide_only {
            assert_eq!(result.probabilities_a.len(), a.len());
            assert_eq!(result.probabilities_b.len(), b.len());
        }
    }
}

#[derive(Debug, Arbitrary)]
struct MeshInput {
    vertices: Vec<[Num; 3]>,
    faces: Vec<[u8; 3]>,
}

impl MeshInput {
    /// The mesh, or `None` where cloudprox rejects it. Face indices are taken
    /// modulo the vertex count (most of them otherwise point past the last
    /// vertex, and almost no input would reach the exact queries); repeated
    /// indices (degenerate faces) still reach `Mesh::new`.
    fn build(&self) -> Option<Mesh> {
        let vertices: Vec<Point3> = self
            .vertices
            .iter()
            .take(32)
            .map(|v| Point3::new(v[0].value(), v[1].value(), v[2].value()))
            .collect();
        let n = u32::try_from(vertices.len()).ok()?.max(1);
        let faces = self
            .faces
            .iter()
            .take(32)
            .map(|f| f.map(|i| u32::from(i) % n))
            .collect();
        Mesh::new(vertices, faces).ok()
    }
}

#[derive(Debug, Arbitrary)]
struct ExactInput {
    a: MeshInput,
    b: MeshInput,
    pose_a: PoseInput,
    pose_b: PoseInput,
    surfaces: bool,
    cloud: CloudInput,
    spacing: Opt<Num>,
}

/// Most points the `exact` target lets `collide_mesh_cloud` sample a mesh into.
const MAX_MESH_SAMPLE: f64 = 1024.0;

/// Exact mesh-vs-mesh proximity on small arbitrary meshes, and the mesh-vs-cloud
/// query (`collide_mesh_cloud`) with the default request.
pub fn exact(data: &[u8]) {
    let Ok(input) = ExactInput::arbitrary_take_rest(Unstructured::new(data)) else {
        return;
    };
    // Any pose, NaN and overflowing ones included: the exact queries and
    // `collide_mesh_cloud` check their poses and reject bad ones.
    let (Some(pose_a), Some(pose_b)) = (input.pose_a.build(), input.pose_b.build()) else {
        return;
    };
    let (Some(a), Some(b)) = (input.a.build(), input.b.build()) else {
        return;
    };
    let shape = |m: &Mesh| {
        let parts = std::slice::from_ref(m);
        if input.surfaces {
            ExactShape::surfaces(parts)
        } else {
            ExactShape::new(parts)
        }
    };
    if let (Ok(sa), Ok(sb)) = (shape(&a), shape(&b)) {
        if let Ok(p) = exact_proximity(&pose_a, &sa, &pose_b, &sb) {
            let _ = p.signed_distance();
        }
        let _ = exact_intersects(&pose_a, &sa, &pose_b, &sb);
    }
    if let Some(cloud) = input.cloud.build() {
        let sampling = MeshSampling {
            spacing: match input.spacing {
                Opt::Default => None,
                Opt::Set(s) => Some(s.value()),
            },
            seed: 7,
            ..MeshSampling::default()
        };
        // One input's work is bounded, as the readers' is by their input size:
        // a mesh sampled into more than `MAX_MESH_SAMPLE` points is left out
        // (the query's cost grows with the sample, not its correctness; a
        // spacing that is not finite and positive still reaches the query).
        let spacing = sampling
            .spacing
            .unwrap_or_else(|| mesh_sampling_spacing(&cloud));
        let samples = a.area() / (spacing * spacing);
        if spacing.is_finite() && spacing > 0.0 && (samples.is_nan() || samples > MAX_MESH_SAMPLE) {
            return;
        }
        let _ = collide_mesh_cloud(
            &pose_a,
            &a,
            &pose_b,
            &cloud,
            &CollisionRequest::default(),
            &sampling,
        );
    }
}

/// A tiny xorshift generator: the smoke test's mutations are reproducible.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }

    /// A number in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// Interesting integers written over a mutated input (libFuzzer's choice).
const MAGIC: [u64; 10] = [
    0,
    1,
    0x7f,
    0xff,
    0x7fff,
    0xffff,
    0x7fff_ffff,
    0xffff_ffff,
    u64::MAX,
    1 << 40,
];

/// One mutation of `seed`: flipped bits, overwritten bytes, magic numbers,
/// a cut, a duplicated or deleted span, or a number in a text header changed.
pub fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut v = seed.to_vec();
    let rounds = 1 + rng.below(4);
    for _ in 0..rounds {
        if v.is_empty() {
            v.push(rng.next_u64() as u8);
            continue;
        }
        let at = rng.below(v.len());
        match rng.below(7) {
            0 => v[at] ^= 1 << rng.below(8),
            1 => v[at] = rng.next_u64() as u8,
            2 => {
                let m = MAGIC[rng.below(MAGIC.len())].to_le_bytes();
                let n = [1, 2, 4, 8][rng.below(4)].min(v.len() - at);
                v[at..at + n].copy_from_slice(&m[..n]);
            }
            3 => v.truncate(at),
            4 => {
                let end = (at + 1 + rng.below(64)).min(v.len());
                let span = v[at..end].to_vec();
                let to = rng.below(v.len());
                v.splice(to..to, span);
            }
            5 => {
                let end = (at + 1 + rng.below(64)).min(v.len());
                v.drain(at..end);
            }
            _ => {
                // A decimal number in the text: replaced by a huge or odd one.
                if let Some(d) = v[at..].iter().position(u8::is_ascii_digit) {
                    let start = at + d;
                    let end = v[start..]
                        .iter()
                        .position(|b| !b.is_ascii_digit())
                        .map_or(v.len(), |e| start + e);
                    let text = [
                        "0",
                        "1",
                        "4294967295",
                        "18446744073709551615",
                        "1000000000000",
                        "-1",
                        "nan",
                    ][rng.below(7)];
                    v.splice(start..end, text.bytes());
                }
            }
        }
    }
    v
}

/// Small inputs every target's corpus starts from, made with cloudprox's own
/// writers (the formats for which no real file is fetched: NPY, XYZ/CSV,
/// PointCloud2, and structured inputs), plus a few texts.
pub fn synthetic_seeds(target: &str) -> Vec<Vec<u8>> {
    let points: Vec<Point3> = (0..12)
        .map(|i| {
            let t = f64::from(i);
            Point3::new(t * 0.01, (t * 0.7).sin() * 0.02, (t * 0.3).cos() * 0.01)
        })
        .collect();
    let mut cloud = CloudData::from_points(points.clone());
    let with_normals = {
        let mut c = cloud.clone();
        c.normals = Some(vec![Vector3::z(); points.len()]);
        c.fields = ["x", "y", "z", "nx", "ny", "nz"].map(String::from).to_vec();
        c
    };
    let with_covs = {
        let mut c = cloud.clone();
        c.covariances = Some(vec![Matrix3::identity() * 1e-6; points.len()]);
        c.fields = ["x", "y", "z"]
            .into_iter()
            .chain(cloudprox::io::COV_FIELDS)
            .map(String::from)
            .collect();
        c
    };
    let tetra = Mesh::new(
        vec![
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.0, 0.0, 1.0),
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    .expect("a tetrahedron is a mesh");
    let mut out = Vec::new();
    let mut push = |r: cloudprox::Result<Vec<u8>>| {
        if let Ok(b) = r {
            out.push(b);
        }
    };
    match target {
        "ply" => {
            for enc in &ENCODINGS[..3] {
                push(ply::write_ply(&with_normals, *enc));
                push(ply::write_ply(&with_covs, *enc));
                push(ply::write_ply_mesh(&tetra, *enc));
            }
        }
        "pcd" => {
            for enc in ENCODINGS {
                push(pcd::write_pcd(&cloud, enc));
                push(pcd::write_pcd(&with_covs, enc));
            }
        }
        "stl" => {
            push(stl::write_stl_mesh(&tetra, Encoding::Ascii));
            push(stl::write_stl_mesh(&tetra, Encoding::BinaryLittleEndian));
        }
        "obj" => push(obj::write_obj_mesh(&tetra)),
        "off" => push(off::write_off_mesh(&tetra)),
        "npy" => {
            push(npy::write_npy(&cloud));
            push(npy::write_npy(&with_covs));
        }
        "xyz" => {
            push(xyz::write_xyz(&cloud, b' '));
            push(xyz::write_xyz(&with_normals, b','));
            push(xyz::write_xyz(&with_covs, b','));
            // Six and nine columns as CGAL, Open3D and CloudCompare write them.
            let text = |cols: &dyn Fn(usize) -> String, header: &str| {
                let mut body = String::from(header);
                for i in 0..12 {
                    body += &[format!("{i}.5 0.25 -1 "), cols(i), "\n".into()].concat();
                }
                body.into_bytes()
            };
            out.push(text(&|i| format!("0.6 0.{} 0.8", i % 2 * 8), ""));
            out.push(text(&|i| format!("{} 20 255", i * 9), ""));
            out.push(text(&|i| format!("{} 20 255 0 0 1", i * 9), ""));
            out.push(text(&|_| "0 1 0 0.5 0.25 1".into(), ""));
            out.push(text(&|_| "1 2 3 0 0 1".into(), "//X Y Z R G B Nx Ny Nz\n"));
        }
        "pointcloud2" => {
            cloud.normals = Some(vec![Vector3::x(); points.len()]);
            if let Ok((layout, data)) = pointcloud2::write_pointcloud2(&cloud) {
                out.push(encode_pc2(&layout, &data));
            }
        }
        "pointcloud2_message" => {
            let organized = pointcloud2::PointCloud2Layout {
                height: 3,
                width: 4,
                ..pointcloud2::write_pointcloud2(&cloud)
                    .map(|(l, _)| l)
                    .expect("a small cloud encodes")
            };
            let mut layout = organized.clone();
            layout.row_step = layout.point_step * layout.width;
            let (_, data) = pointcloud2::write_pointcloud2(&cloud).expect("a small cloud encodes");
            let header = pointcloud2::PointCloud2Header {
                stamp_ns: 1_700_000_000_000_000_000,
                frame_id: "velodyne".into(),
                is_dense: false,
            };
            for (pick, encoding) in [
                (0u8, pointcloud2::MessageEncoding::Cdr),
                (1u8, pointcloud2::MessageEncoding::Ros1),
            ] {
                let mut m = vec![pick];
                m.extend(pointcloud2::encode_pointcloud2(
                    &header, &layout, &data, encoding,
                ));
                out.push(m);
            }
        }
        "urdf" => out.push(URDF_SEED.as_bytes().to_vec()),
        "srdf" => out.push(SRDF_SEED.as_bytes().to_vec()),
        _ => {}
    }
    // Structured targets: a few byte patterns give whole inputs.
    if matches!(target, "collide" | "exact" | "pointcloud2") {
        for k in 0..8u8 {
            out.push(
                (0..600u32)
                    .map(|i| (i as u8).wrapping_mul(k + 1) ^ k)
                    .collect(),
            );
        }
    }
    out
}

/// The bytes from which [`pointcloud2`] rebuilds `layout` and `data` (the
/// inverse of its `arbitrary` decoding, for a seed).
fn encode_pc2(layout: &pointcloud2::PointCloud2Layout, data: &[u8]) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend(layout.height.to_le_bytes());
    b.extend(layout.width.to_le_bytes());
    // A Vec's elements follow while a `true` byte precedes each.
    for f in &layout.fields {
        b.push(1);
        let name = PC2_NAMES.iter().position(|n| *n == f.name).unwrap_or(6);
        b.push(name as u8);
        b.extend(f.offset.to_le_bytes());
        b.push(f.datatype);
        b.extend(f.count.to_le_bytes());
    }
    b.push(0);
    b.push(u8::from(layout.is_bigendian));
    b.extend(layout.point_step.to_le_bytes());
    b.extend(layout.row_step.to_le_bytes());
    b.push(0); // not tame
    b.extend(data);
    b
}

/// A small SRDF for [`URDF_SEED`]: a group and two `<disable_collisions>`.
pub const SRDF_SEED: &str = r#"<?xml version="1.0"?>
<robot name="seed">
  <group name="arm"><chain base_link="base" tip_link="tip"/></group>
  <disable_collisions link1="base" link2="arm" reason="Adjacent"/>
  <disable_collisions link1="arm" link2="tip" reason="Never"></disable_collisions>
</robot>
"#;

/// A small URDF: two links, a revolute joint, box, sphere and cylinder shapes.
pub const URDF_SEED: &str = r#"<?xml version="1.0"?>
<robot name="seed">
  <link name="base">
    <collision><origin xyz="0 0 0.05" rpy="0 0 0"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <collision><geometry><cylinder radius="0.03" length="0.4"/></geometry></collision>
    <collision><origin xyz="0 0 0.2"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <link name="tip"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0 0 0.1" rpy="0 0 1.57"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="j2" type="prismatic">
    <parent link="arm"/><child link="tip"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/>
    <mimic joint="j1" multiplier="0.5" offset="0"/>
  </joint>
</robot>
"#;

/// The real files (fetched by the Python tests into `<cache>/realfiles`) that
/// seed target `target`: path suffixes matched against the cache's files.
pub fn real_seed_extensions(target: &str) -> &'static [&'static str] {
    match target {
        "ply" => &[".ply"],
        "pcd" => &[".pcd"],
        "las" => &[".las", ".laz"],
        "stl" => &[".stl"],
        "obj" => &[".obj"],
        "off" => &[".off"],
        "urdf" => &[".urdf"],
        _ => &[],
    }
}
