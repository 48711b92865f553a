//! The conemap command-line tool. Thin: argument parsing and printing only.
//!
//! `conemap <command> [args]`; each command is one function taking the
//! arguments after its name, listed in [`COMMANDS`] and dispatched by [`run`].

use conemap::cones::{self, BoundaryMode, ConeOptions, ConePlacement};
use conemap::features::FeatureSet;
use conemap::pipeline::GridFeatures;
use conemap::mesh::{analyze_located, Located, RawMesh, TriMesh};
use conemap::param::quantize::{GridSize, QuantizeOptions, QuantizeReport};
use std::path::Path;
use std::process::ExitCode;

/// `println!` that ends the program quietly when standard output is closed
/// (piped into `head`, say) instead of panicking.
macro_rules! println {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout(), $($arg)*) {
            $crate::stdout_failed(e)
        }
    }};
}

// After the `println!` above, which it uses too.
#[path = "conemap/quads.rs"]
mod quads;

/// Exits after a failed write to standard output: silently (status 0) when
/// the reader went away, else with the error on standard error (status 1).
fn stdout_failed(e: std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    eprintln!("conemap: cannot write to standard output: {e}");
    std::process::exit(1);
}

const USAGE: &str = "\
usage: conemap <command> [options]

commands:
  info FILE [--json]   read a mesh (.obj, .gltf, .glb) and report its figures
                       (vertices, faces, boundary, components, Euler
                       characteristic, genus) and every problem found.
                       --json prints one JSON object instead.

  cones FILE [--alpha A] [--miq] [--quiet] [--sharp DEG] [--min-feature-length N|X%]
             [--closed-features] [--features FEATURES.json]
             [--boundary aligned|free] [--max-cone-index K] [--max-edge L|X%|none]
             [--no-moves] [--json]
                       place cones (Myles & Zorin 2013, sections 4-5).
                       --alpha: alpha_smooth, 1e-4..1e3 (default 0.01; 100
                       with --miq). --miq: MIQ emulation (no harmonic
                       minimality). --sharp: edges with dihedral angle above
                       DEG degrees are features; --min-feature-length N
                       drops sharp curves (connected sets of sharp edges)
                       of fewer than N edges, or shorter than X % of the
                       bounding-box diagonal when given as X%;
                       --closed-features drops dangling sharp ends, keeping
                       closed curves and curves that end on other features
                       or boundaries. --features: a JSON file
                       {\"edges\": [[[x,y,z],[x,y,z]], ...]} of feature edges
                       by end positions. --boundary free: leave the mesh's
                       boundary off the isolines (no corners; for scans with
                       holes and texture atlases; features stay aligned);
                       default aligned. --max-cone-index K: largest index of
                       an interior cone, 1..3 (default 1: every cone has
                       quad valence 4 - k >= 3; 2 or 3 allow the fewer,
                       sharper cones a UV map may prefer, e.g. one of
                       index 3 on a horn tip). --max-edge: first split
                       edges longer than L model units (X% of the bounding-
                       box diagonal), flipping edges between coplanar
                       triangles to keep them well shaped: more vertices
                       for the cones and the map on a low-poly mesh (a CAD
                       export); default none (quads: 5% or 3.5 quads,
                       whichever is shorter; solve splits to 5% only where
                       the map of a low-poly mesh folds).
                       --no-moves: skip the cone-location optimization
                       (with features, solve and quads otherwise also map
                       the placement without moves and keep the better
                       map). --json prints one JSON object.
                       On a terminal, the stage and its progress (rounding
                       round and integers left, cone-move pass, ARAP and
                       injective iterations) show on standard error while
                       it runs; --quiet turns that off.

  solve FILE -o OUT [--alpha A] [--miq] [--quiet] [--sharp DEG|none] [--min-feature-length N|X%]
             [--closed-features] [--features FEATURES.json]
             [--boundary aligned|free] [--max-cone-index K] [--no-moves] [--report REPORT.json] [--checker]
                       place cones, compute the seamless parametrization and
                       write the mesh with UVs to OUT: .glb, .gltf (buffer
                       embedded) or .obj, by extension. Vertices are split
                       exactly along the UV seams. UVs are normalised into
                       [0,1] preserving aspect; glTF stores (u, 1-v), OBJ
                       (u, v). A glTF input keeps its primitives, materials
                       (factors) and normals. Cone options as for cones.
                       --report: write a JSON report (the cones --json
                       fields plus metrics and per-stage timings).
                       --checker: embed a checkerboard texture (glTF),
                       squares of 2^-k UV units (at least 16 across).
                       --grid S / --quads N: make the map an integer-grid
                       map of cell S (model units), or of about N cells:
                       cones on integer points, features and boundary on
                       integer isolines, seam translations integers. UVs
                       are then in grid units (one cell = 1.0, shifted by
                       an integer only) and the checker square is a cell.
                       Opposite cones closer than a cell's diagonal cancel
                       (the grid cannot keep them apart). Where that map
                       folds on a mesh with edges longer than such quads
                       (a low-poly CAD export), it is solved again with
                       those edges split; the output is then the refined
                       mesh. Where it still folds, it is solved again
                       without the feature curves the grid is too coarse
                       to follow (dangling branches and closed loops under
                       two cells) and the map that folds less is kept
                       (the report's dropped_feature_edges counts them).
                       Without --sharp or --features, a grid map follows
                       the mesh's creases (edges sharper than 75° on
                       curves of at least 10 % of the bounding-box
                       diagonal: a CAD part's edges, which quads cut across
                       otherwise); where they fold the map, those next
                       to the folds are dropped, or where that still
                       folds, all on that part (the report's
                       detected_feature_edges counts them); --sharp none
                       follows no crease.

  quads FILE -o OUT.obj|OUT.glb [--quad-size S | --quads N] [--alpha A] [--sharp DEG|none]
             [--features FEATURES.json] [--report REPORT.json] [--full-mesh] [cone options]
                       the quad mesh of the integer-grid map (default
                       --quads 3000): OBJ with quad faces and the grid
                       coordinates of each corner as vt; glTF with each quad
                       as two triangles plus the quad edges as LINES.
                       --report: quads, singular vertices by valence,
                       corner-angle statistics, distortion before and after
                       quantization, defects and per-stage timings. The
                       map is solved on the input refined to --max-edge 5%
                       or 3.5 quads, whichever is shorter (the quads lie on
                       the input surface all the same), and opposite cones
                       closer than a quad's diagonal cancel. Where the map
                       folds, it is solved again without the feature
                       curves under two quads that dangle or close on
                       themselves, and the map that folds less is kept
                       (a note and the report's dropped_feature_edges say
                       so; the sharp-edge figures still count them).
                       Without --sharp or --features, creases are followed
                       as for solve --grid (--sharp none: none).
                       A mesh of more than 16 faces per quad is first
                       decimated to about 8 per quad, keeping its boundary
                       and feature curves; the quads traced on it are
                       moved onto the input and untangled there (the
                       report's decimated). Where they fold, they are
                       traced again on a decimation twice as fine (below
                       32 faces per quad: on the input) and the better
                       kept. --full-mesh solves on every face instead.

options:
  -h, --help           print this help

Exit status: 0 on success (for info: when the file was read, even if it has
problems), 1 when the input could not be read, parsed or used, 2 for bad usage.";

/// Commands and the flags they accept.
const COMMANDS: &[(&str, &[&str])] = &[
    ("info", &["--json"]),
    (
        "cones",
        &["--json", "--quiet", "--miq", "--no-moves", "--closed-features", "--alpha=", "--sharp=", "--min-feature-length=", "--features=", "--boundary=", "--max-cone-index=", "--max-edge="],
    ),
    (
        "solve",
        &[
            "--quiet",
            "--miq",
            "--no-moves",
            "--checker",
            "--closed-features",
            "--alpha=",
            "--sharp=",
            "--min-feature-length=",
            "--features=",
            "--boundary=",
            "--max-cone-index=",
            "--max-edge=",
            "--report=",
            "--grid=",
            "--quads=",
            "-o=",
            "--output=",
        ],
    ),
    (
        "quads",
        &[
            "--quiet",
            "--miq",
            "--no-moves",
            "--closed-features",
            "--alpha=",
            "--sharp=",
            "--min-feature-length=",
            "--features=",
            "--boundary=",
            "--max-cone-index=",
            "--max-edge=",
            "--report=",
            "--quad-size=",
            "--quads=",
            "--full-mesh",
            "-o=",
            "--output=",
        ],
    ),
];

/// A failure: the one-line message and the exit status.
struct Failure(String, u8);

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure(msg, code)) => {
            eprintln!("conemap: {msg}");
            ExitCode::from(code)
        }
    }
}

fn run(args: &[String]) -> Result<(), Failure> {
    let Some(cmd) = args.first() else {
        return Err(usage("no command given"));
    };
    match cmd.as_str() {
        "-h" | "--help" | "help" => {
            println!("{USAGE}");
            Ok(())
        }
        name => {
            let Some(&(_, flags)) = COMMANDS.iter().find(|(n, _)| *n == name) else {
                return Err(usage(&format!("unknown command \"{name}\"")));
            };
            let parsed = Args::parse(&args[1..], flags)?;
            if parsed.help {
                println!("{USAGE}");
                return Ok(());
            }
            match name {
                "info" => info_command(&parsed),
                "cones" => cones_command(&parsed),
                "solve" => solve_command(&parsed),
                "quads" => quads::quads_command(&parsed),
                _ => unreachable!("command listed in COMMANDS without a handler"),
            }
        }
    }
}

fn usage(msg: &str) -> Failure {
    Failure(format!("{msg} (try `conemap --help`)"), 2)
}

/// Positional arguments, `--flag`s and `--option value`s of one command
/// (an allowed name ending in `=` takes a value).
struct Args {
    positional: Vec<String>,
    flags: Vec<String>,
    values: Vec<(String, String)>,
    help: bool,
}

impl Args {
    fn parse(args: &[String], allowed: &[&str]) -> Result<Args, Failure> {
        let mut out = Args { positional: Vec::new(), flags: Vec::new(), values: Vec::new(), help: false };
        let mut only_positional = false;
        let mut it = args.iter();
        while let Some(a) = it.next() {
            let (name, inline) = match a.split_once('=') {
                Some((n, v)) if a.starts_with("--") => (n, Some(v.to_string())),
                _ => (a.as_str(), None),
            };
            if !only_positional && allowed.contains(&format!("{name}=").as_str()) {
                let value = match inline {
                    Some(v) => v,
                    None => it.next().cloned().ok_or_else(|| usage(&format!("{name} needs a value")))?,
                };
                out.values.push((name.to_string(), value));
            } else if only_positional || !a.starts_with('-') || a == "-" {
                out.positional.push(a.clone());
            } else if a == "--" {
                only_positional = true;
            } else if a == "-h" || a == "--help" {
                out.help = true;
            } else if allowed.contains(&a.as_str()) {
                out.flags.push(a.clone());
            } else {
                return Err(usage(&format!("unknown option \"{a}\"")));
            }
        }
        Ok(out)
    }
    fn flag(&self, name: &str) -> bool {
        self.flags.iter().any(|f| f == name)
    }
    /// The value of `--name`, parsed as a number, if given.
    fn number(&self, name: &str) -> Result<Option<f64>, Failure> {
        match self.values.iter().rev().find(|(n, _)| n == name) {
            None => Ok(None),
            Some((_, v)) => v
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .map(Some)
                .ok_or_else(|| usage(&format!("{name} expects a number, got \"{v}\""))),
        }
    }
    /// The value of `--name`, if given.
    fn value(&self, name: &str) -> Option<&str> {
        self.values.iter().rev().find(|(n, _)| n == name).map(|(_, v)| v.as_str())
    }
    /// The single positional FILE argument.
    fn file(&self) -> Result<&str, Failure> {
        match self.positional.as_slice() {
            [f] => Ok(f),
            [] => Err(usage("missing FILE")),
            _ => Err(usage("expected exactly one FILE")),
        }
    }
}

fn info_command(args: &Args) -> Result<(), Failure> {
    let file = args.file()?;
    let input = conemap::io::import_path_numbered(Path::new(file)).map_err(|e| Failure(e.to_string(), 1))?;
    let located = analyze_located(&input.raw, &input.numbering);
    if args.flag("--json") {
        let json = serde_json::to_string(&located.report).map_err(|e| Failure(e.to_string(), 1))?;
        println!("{json}");
    } else {
        print_report(file, &located);
    }
    Ok(())
}

/// Prints the figures of `located` and its problems, named as the file numbers its elements.
fn print_report(file: &str, located: &Located) {
    let r = &located.report;
    println!("{file}");
    println!(
        "  vertices: {} (source vertices: {}, merged by welding: {})",
        r.vertices, r.source_vertices, r.merged_vertices
    );
    println!("  faces: {}", r.faces);
    println!(
        "  edges: {} (boundary: {}, non-manifold: {})",
        r.edges, r.boundary_edges, r.non_manifold_edges
    );
    println!("  boundary loops: {}", r.boundary_loops);
    println!(
        "  components: {} edge-connected ({} when touching at a vertex counts)",
        r.components, r.vertex_connected_components
    );
    println!("  Euler characteristic: {}", r.euler_characteristic);
    const MAX_COMPONENTS: usize = 20;
    for c in 0..r.components.min(MAX_COMPONENTS) {
        let genus = if r.component_is_manifold[c] {
            format!("genus {}", r.genus[c])
        } else {
            "non-manifold".to_string()
        };
        println!(
            "    component {c}: {} faces, Euler characteristic {}, {} boundary loops, {genus}",
            r.faces_per_component[c], r.euler_characteristic_per_component[c], r.boundary_loops_per_component[c]
        );
    }
    if r.components > MAX_COMPONENTS {
        println!("    … and {} more components", r.components - MAX_COMPONENTS);
    }
    let blocking = r.problems.iter().filter(|p| p.is_blocking()).count();
    if r.problems.is_empty() {
        println!("  problems: none");
    } else {
        println!("  problems: {} ({blocking} blocking)", r.problems.len());
        const MAX_PROBLEMS: usize = 50;
        for p in located.problems.iter().take(MAX_PROBLEMS) {
            println!("    {}", p.message);
        }
        if r.problems.len() > MAX_PROBLEMS {
            println!("    … and {} more (use --json for all)", r.problems.len() - MAX_PROBLEMS);
        }
    }
}

/// Reads FILE and builds the validated mesh; problems become one message.
fn load_mesh(file: &str) -> Result<TriMesh, Failure> {
    let input = conemap::io::import_path_numbered(Path::new(file)).map_err(|e| Failure(e.to_string(), 1))?;
    validated(file, &input.raw, &input.numbering)
}

/// The validated mesh of `raw`, or a failure naming its first blocking
/// problem (elements numbered as the file does) and how many there are.
fn validated(file: &str, raw: &RawMesh, numbering: &conemap::io::FileNumbering) -> Result<TriMesh, Failure> {
    TriMesh::from_raw(raw).map_err(|problems| {
        let located = analyze_located(raw, numbering);
        let first = located.problems.iter().find(|p| p.blocking).map(|p| p.message.clone()).unwrap_or_default();
        let more = if problems.len() > 1 { format!(" (and {} more problems)", problems.len() - 1) } else { String::new() };
        Failure(format!("{file}: cannot be parametrized: {first}{more}"), 1)
    })
}

/// Feature edges from `--sharp` and `--features`.
fn load_features(args: &Args, mesh: &TriMesh) -> Result<FeatureSet, Failure> {
    use conemap::features::{detect_sharp, MinLength, SharpOptions};
    let mut features = FeatureSet::none(mesh);
    let min_length = match args.value("--min-feature-length") {
        None => MinLength::None,
        Some(v) => {
            let bad = || usage(&format!("--min-feature-length expects a number of edges or a percentage (\"2%\"), got \"{v}\""));
            match v.strip_suffix('%') {
                Some(p) => MinLength::DiagonalFraction(p.parse::<f64>().ok().filter(|x| x.is_finite() && *x >= 0.0).ok_or_else(bad)? / 100.0),
                None => MinLength::Edges(v.parse::<usize>().map_err(|_| bad())?),
            }
        }
    };
    let filtering = min_length != MinLength::None || args.flag("--closed-features");
    let threshold = if args.value("--sharp") == Some("none") { None } else { args.number("--sharp")? };
    if let Some(deg) = threshold {
        let found = detect_sharp(mesh, &SharpOptions { threshold_degrees: deg, min_length, prune_dangling: args.flag("--closed-features") });
        if filtering {
            let s = found.stats;
            eprintln!(
                "conemap: sharp edges > {deg}°: {} edges; kept {} curves ({} edges), dropped {} short fragments and {} dangling edges",
                s.sharp_edges, s.curves, s.kept_edges, s.dropped_fragments, s.pruned_edges
            );
        }
        features.union(&found.features);
    } else if filtering {
        return Err(usage("--min-feature-length and --closed-features filter --sharp: give --sharp DEG"));
    }
    if let Some(path) = args.value("--features") {
        let text = std::fs::read_to_string(path).map_err(|e| Failure(format!("{path}: {e}"), 1))?;
        let edges = conemap::io::parse_feature_edges(&text).map_err(|e| Failure(format!("{path}: {e}"), 1))?;
        let given = FeatureSet::from_positions(mesh, &edges).map_err(|e| Failure(format!("{path}: {e}"), 1))?;
        features.union(&given);
    }
    Ok(features)
}

/// The features of a grid map (`quads`, `solve --grid`): those of
/// [`load_features`], or where neither `--sharp` nor `--features` is given,
/// the creases of [`conemap::features::CREASES`], which the grid stage
/// drops on the components where they fold the map (`--sharp none`: none).
fn grid_features(args: &Args, mesh: &TriMesh) -> Result<GridFeatures, Failure> {
    let asked = load_features(args, mesh)?;
    if args.value("--sharp").is_some() || args.value("--features").is_some() {
        return Ok(GridFeatures::asked(mesh, asked));
    }
    let creases = conemap::features::detect_sharp(mesh, &conemap::features::CREASES).features;
    Ok(GridFeatures::detected(creases))
}

/// Both stages' settings: [`cone_options`] and `--max-edge L|X%` (split
/// edges longer than L model units, or X % of `mesh`'s bounding-box
/// diagonal, before the cones); `default_max_edge` when the flag is absent.
fn solve_options(args: &Args, mesh: &TriMesh, default_max_edge: Option<f64>) -> Result<conemap::pipeline::SolveOptions, Failure> {
    let mut options = conemap::pipeline::SolveOptions { cones: cone_options(args)?, ..Default::default() };
    options.refine.max_edge_length = match args.value("--max-edge") {
        None => default_max_edge,
        Some("none") => None,
        Some(v) => {
            let bad = || usage(&format!("--max-edge expects a positive length, a percentage (\"2%\") or none, got \"{v}\""));
            let (number, fraction) = match v.strip_suffix('%') {
                Some(p) => (p, true),
                None => (v, false),
            };
            let x = number.parse::<f64>().ok().filter(|x| x.is_finite() && *x > 0.0).ok_or_else(bad)?;
            let length = if fraction { x / 100.0 * mesh.bounding_diagonal() } else { x };
            let (faces, most) = (conemap::features::faces_for_length(mesh, length), conemap::features::MAX_REFINED_FACES);
            if faces > most as f64 {
                return Err(usage(&format!("--max-edge {v} would split the mesh into about {faces:.0} triangles (at most {most}): give a longer length")));
            }
            Some(length)
        }
    };
    Ok(options)
}

fn cone_options(args: &Args) -> Result<ConeOptions, Failure> {
    let miq = args.flag("--miq");
    let default_alpha = if miq { cones::MIQ_ALPHA } else { cones::DEFAULT_ALPHA };
    let alpha = args.number("--alpha")?.unwrap_or(default_alpha);
    let (lo, hi) = cones::ALPHA_RANGE;
    if !(lo..=hi).contains(&alpha) {
        return Err(usage(&format!("--alpha {alpha} is outside {lo}..{hi}")));
    }
    let boundary = match args.value("--boundary") {
        None | Some("aligned") => BoundaryMode::Aligned,
        Some("free") => BoundaryMode::Free,
        Some(other) => return Err(usage(&format!("--boundary expects aligned or free, got \"{other}\""))),
    };
    let max_cone_index = match args.number("--max-cone-index")? {
        None => ConeOptions::default().max_cone_index,
        Some(k) if [1.0, 2.0, 3.0].contains(&k) => k as i64,
        Some(k) => return Err(usage(&format!("--max-cone-index expects 1, 2 or 3, got {k}"))),
    };
    Ok(ConeOptions {
        alpha_smooth: alpha,
        miq,
        optimize_locations: !args.flag("--no-moves"),
        boundary,
        max_cone_index,
        ..ConeOptions::default()
    })
}

/// The stage and its progress on one line of standard error, while a long
/// command runs: only when standard error is a terminal and `--quiet` is
/// not given (nothing is printed otherwise).
struct ProgressLine(Option<indicatif::ProgressBar>);

impl ProgressLine {
    fn new(args: &Args) -> ProgressLine {
        use std::io::IsTerminal as _;
        if args.flag("--quiet") || !std::io::stderr().is_terminal() {
            return ProgressLine(None);
        }
        let bar = indicatif::ProgressBar::new_spinner();
        bar.set_style(indicatif::ProgressStyle::with_template("{spinner} {elapsed:>4} {msg}").expect("valid template"));
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
        ProgressLine(Some(bar))
    }

    fn say(&self, message: impl FnOnce() -> String) {
        if let Some(bar) = &self.0 {
            bar.set_message(message());
        }
    }

    fn cones(&self, p: &cones::ConeProgress) {
        use cones::ConeProgress::*;
        self.say(|| match *p {
            Topology { component, components } => format!("cones: component {} of {components}, path basis", component + 1),
            Rounding { component, round, free } => {
                format!("cones: component {}, rounding round {round}, {free} integers free", component + 1)
            }
            ConeMoves { component, pass, tried, cones } => {
                format!("cones: component {}, cone moves, pass {}, {tried} of {cones} cones tried", component + 1, pass + 1)
            }
            PairCancellation { component, removed, tried, trials } => {
                format!("cones: component {}, pair cancellation, {removed} removed, {tried} of {trials} pairs tried", component + 1)
            }
        });
    }

    fn param(&self, p: &conemap::param::ParamProgress) {
        use conemap::param::ParamProgress::*;
        self.say(|| match *p {
            Field => "parametrization: cross field".to_string(),
            Cut => "parametrization: cut graph".to_string(),
            Poisson => "parametrization: Poisson solve".to_string(),
            Arap { iteration, max } => format!("parametrization: ARAP iteration {iteration} of at most {max}"),
            Repair { round, flips } => format!("parametrization: fold-over repair round {round}, {flips} flipped"),
            Injective { iteration, max } => format!("parametrization: injective iteration {iteration} of at most {max}"),
        });
    }

    fn solve(&self, p: conemap::pipeline::SolveProgress) {
        match p {
            conemap::pipeline::SolveProgress::Cones(p) => self.cones(&p),
            conemap::pipeline::SolveProgress::Param(p) => self.param(&p),
        }
    }

    fn quads(&self, p: conemap::pipeline::QuadProgress) {
        use conemap::pipeline::QuadProgress::*;
        match p {
            Decimate { faces_per_quad } => self.say(|| format!("decimating to {faces_per_quad} faces per quad")),
            Solve(p) => self.solve(p),
            Quantize { done, total } => self.say(|| format!("quantization: {done} of {total} integers rounded")),
            Extract => self.say(|| "quad extraction".to_string()),
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.0 {
            bar.finish_and_clear();
        }
    }
}

fn cones_command(args: &Args) -> Result<(), Failure> {
    let file = args.file()?;
    let mesh = load_mesh(file)?;
    let features = load_features(args, &mesh)?;
    let solve_options = solve_options(args, &mesh, None)?;
    let options = solve_options.cones;
    let bar = ProgressLine::new(args);
    let placed = conemap::pipeline::place_cones(&mesh, &features, &solve_options, &mut |p| bar.cones(&p));
    bar.finish();
    let placed = placed.map_err(|e| Failure(format!("{file}: {e}"), 1))?;
    let (solved, result) = (placed.mesh(&mesh), &placed.placement);
    let (splits, counts) = placed.refinement();
    if args.flag("--json") {
        let mut json = cones_json(solved, &features, &options, result);
        json["inserted_vertices"] = serde_json::json!(splits);
        json["refinement"] = serde_json::json!(counts);
        println!("{json}");
    } else {
        print_cones(file, solved, &features, &options, result);
        if splits > 0 {
            println!("  note: {}; cones are on the refined mesh", refinement_note(splits, &counts));
        }
    }
    Ok(())
}

/// What the refinement before the cone stage inserted, in words.
fn refinement_note(splits: usize, r: &conemap::features::RefineCounts) -> String {
    format!(
        "inserted {splits} vertices ({} lone feature edges opened, {} triangles with three and {} with two constrained edges split, \
         {} enclosed regions given an interior vertex, {} faces split around cones of angle 0, {} long edges of flipped triangles split, {} edges over the maximum length split)",
        r.lone_edges, r.triply_constrained, r.doubly_constrained, r.enclosed_regions, r.zero_angle_faces, r.flipped_edges, r.long_edges
    )
}

fn cones_json(mesh: &TriMesh, features: &FeatureSet, options: &ConeOptions, r: &ConePlacement) -> serde_json::Value {
    serde_json::json!({
        "vertices": mesh.n_vertices(),
        "faces": mesh.n_faces(),
        "feature_edges": features.len(),
        "alpha_smooth": options.alpha_smooth,
        "miq": options.miq,
        "boundary": options.boundary,
        "euler_characteristic": mesh.euler_characteristic(),
        "cones": r.cones,
        "boundary_corners": r.boundary_corners,
        "components": r.components,
        "rounds": r.rounds,
        "energy": r.energy,
        "phi_rms": r.phi_rms,
        "timings": r.timings,
    })
}

fn print_cones(file: &str, mesh: &TriMesh, features: &FeatureSet, options: &ConeOptions, r: &ConePlacement) {
    println!("{file}: {} vertices, {} faces, {} feature edges", mesh.n_vertices(), mesh.n_faces(), features.len());
    println!(
        "  alpha_smooth {}{}: {} cones ({} positive, {} negative), {} boundary corners",
        options.alpha_smooth,
        if options.miq { " (MIQ emulation)" } else { "" },
        r.cones.len(),
        r.cones.iter().filter(|c| c.k > 0).count(),
        r.cones.iter().filter(|c| c.k < 0).count(),
        r.boundary_corners.len()
    );
    let k_sum: i32 = r.cones.iter().chain(&r.boundary_corners).map(|c| c.k).sum();
    if options.boundary == BoundaryMode::Free && !mesh.boundary_loops().is_empty() {
        // The free boundary's geodesic curvature takes the rest of 4 chi.
        println!("  sum of k: {k_sum} (free boundary: no corners)");
    } else {
        println!("  sum of k: {k_sum} (4 chi = {})", 4 * mesh.euler_characteristic());
    }
    println!("  energy {:.6}, phi rms {:.6}, {} rounding rounds", r.energy, r.phi_rms, r.rounds);
    let t = &r.timings;
    println!(
        "  time: cut {:.3} s, topology {:.3} s, rounding {:.3} s, cone moves {:.3} s, total {:.3} s",
        t.cut, t.topology, t.rounding, t.cone_moves, t.total
    );
}

/// `solve`: import, cones, parametrization, export.
/// `conemap solve`: read, place cones, parametrize, write the mesh with UVs
/// (and the report when asked), print the summary.
fn solve_command(args: &Args) -> Result<(), Failure> {
    use conemap::export::{self, ExportInput, ExportOptions, Format};

    let file = args.file()?;
    let out = args.value("-o").or_else(|| args.value("--output")).ok_or_else(|| usage("solve needs -o OUT"))?;
    let Some(format) = Format::from_path(out) else {
        return Err(usage(&format!("{out}: unknown output format (use .glb, .gltf or .obj)")));
    };
    cone_options(args)?;
    let grid = grid_option(args, "--grid")?;
    // Fail before the long computation when the output cannot be created.
    check_writable([Some(out), args.value("--report")].into_iter().flatten())?;

    let mut clock = conemap::clock::Stopwatch::start();
    let input_file = read_input(file)?;
    let mut times = SolveTimes { import: clock.lap(), ..SolveTimes::default() };
    let features = match grid {
        Some(_) => grid_features(args, &input_file.mesh)?,
        None => GridFeatures::asked(&input_file.mesh, load_features(args, &input_file.mesh)?),
    };
    let mut options = solve_options(args, &input_file.mesh, None)?;
    if let Some(grid) = grid {
        options = options.for_quads(&input_file.mesh, grid);
    }
    let mut solution = solve_mesh(args, file, &input_file.mesh, &features.all, &options)?;
    times.cones = solution.refine_seconds + solution.placement.timings.total;
    times.param = clock.lap() - times.cones;
    let (mut grid_map, mut dropped_features) = (None, FeatureSet::none(&input_file.mesh));
    if let Some(size) = grid {
        // A map solved again on the refinement for quads (where the input's
        // grid map folds) counts as quantization time.
        let bar = ProgressLine::new(args);
        let quantize = QuantizeOptions { retry_wound: true, ..QuantizeOptions::default() };
        let long_edges = conemap::pipeline::LongEdges::RefineWhereFolded;
        let mapped = conemap::pipeline::grid_map(&input_file.mesh, &features, &options, solution, size, &quantize, long_edges, &mut |p| bar.solve(p), &mut |_, _| {});
        bar.finish();
        let mapped = mapped.map_err(|e| Failure(format!("{file}: {e}"), 1))?;
        dropped_features = mapped.dropped_features;
        (solution, grid_map) = (mapped.solution, Some(mapped.map));
    }
    let alignment = solution.feature_alignment(&input_file.mesh, &features.all);
    times.quantize = clock.lap();
    let uv = grid_map.as_ref().map(|g| &g.uv).unwrap_or(&solution.param.uv);

    // Splitting doubly constrained triangles adds vertices: export the refined
    // mesh then (its source attributes are not carried over).
    let refined_raw;
    let (raw_used, source_used) = if solution.splits > 0 {
        refined_raw = RawMesh { positions: solution.mesh.positions().to_vec(), triangles: solution.mesh.faces().to_vec() };
        (&refined_raw, None)
    } else {
        (&input_file.raw, input_file.source.as_ref())
    };
    let mut input = ExportInput::new(raw_used, &solution.mesh, uv).map_err(|e| Failure(format!("{file}: {e}"), 1))?;
    if let Some(source) = source_used {
        input = input.with_gltf_source(source, &input_file.main, &input_file.others);
    }
    let stem = Path::new(file).file_stem().map(|s| s.to_string_lossy().into_owned());
    let export_options = ExportOptions {
        checker: args.flag("--checker"),
        checker_cell: grid_map.as_ref().map(|_| 1.0),
        name: stem,
        grid_units: grid_map.is_some(),
    };
    let data = export::export(&input, format, &export_options);
    std::fs::write(out, &data).map_err(|e| Failure(format!("{out}: cannot write: {e}"), 1))?;
    times.export = clock.lap();

    let written = Written { path: out, format, input: &input, options: &export_options, bytes: data.len() };
    if let Some(path) = args.value("--report") {
        let mut report = solve_report(&solution, &options.cones, &alignment, &written, &times);
        if let Some(g) = &grid_map {
            report["quantization"] = serde_json::json!(g.report);
            report["dropped_feature_edges"] = serde_json::json!(dropped_features.len());
            report["detected_feature_edges"] = serde_json::json!(features.detected.len());
        }
        let text = serde_json::to_string_pretty(&report).map_err(|e| Failure(e.to_string(), 1))?;
        std::fs::write(path, text + "\n").map_err(|e| Failure(format!("{path}: cannot write: {e}"), 1))?;
    }
    print_solution(file, &solution, &alignment, &written, &times);
    if let Some(g) = &grid_map {
        print_dropped_features(&features, &dropped_features);
        print_quantization(&g.report);
    }
    Ok(())
}

/// Places cones and parametrizes `mesh` (read from `file`) with the cone
/// options of `args`, showing progress on a terminal.
fn solve_mesh<'a>(
    args: &Args,
    file: &str,
    mesh: &'a TriMesh,
    features: &'a FeatureSet,
    options: &conemap::pipeline::SolveOptions,
) -> Result<conemap::pipeline::Solution<'a>, Failure> {
    use conemap::pipeline;
    let bar = ProgressLine::new(args);
    let solution = pipeline::solve(mesh, features, options, &mut |p| bar.solve(p));
    bar.finish();
    solution.map_err(|e| Failure(format!("{file}: {e}"), 1))
}

/// The grid size of `--grid S` / `--quad-size S` (`flag`) or `--quads N`; `None` when neither is given.
fn grid_option(args: &Args, flag: &str) -> Result<Option<GridSize>, Failure> {
    let size = args.number(flag)?;
    let quads = args.number("--quads")?;
    match (size, quads) {
        (Some(_), Some(_)) => Err(usage(&format!("give {flag} or --quads, not both"))),
        (Some(s), None) if s > 0.0 && s.is_finite() => Ok(Some(GridSize::Length(s))),
        (Some(s), None) => Err(usage(&format!("{flag} expects a positive length, got {s}"))),
        (None, Some(n)) if n >= 1.0 && n.fract() == 0.0 && n <= 1e8 => Ok(Some(GridSize::Quads(n as usize))),
        (None, Some(n)) => Err(usage(&format!("--quads expects a whole number of quads, got {n}"))),
        (None, None) => Ok(None),
    }
}

/// The notes on the feature edges a grid map was solved without
/// ([`conemap::pipeline::grid_map`]) and on the creases it detected, if any.
fn print_dropped_features(features: &GridFeatures, dropped: &FeatureSet) {
    let detected = &features.detected;
    let asked = dropped.without(detected).len();
    if asked > 0 {
        println!(
            "  note: the map with every feature folds; solved without {asked} feature edges: those the grid is too coarse to follow (branches and loops under {} quads), then those next to the folds; a smaller grid keeps more of them",
            conemap::features::grid::MIN_CURVE_CELLS
        );
    }
    if !detected.is_empty() {
        let kept = detected.without(dropped).len();
        println!("  creases (no --sharp or --features given): {kept} of {} crease edges followed; --sharp none turns this off", detected.len());
    }
}

/// The summary of a quantization.
fn print_quantization(r: &QuantizeReport) {
    println!(
        "  integer grid: cell {:.4} ({:.0} cells), {} point and {} translation integers in {} batches, distortion {:.4} -> {:.4}, flipped {}, integer residual {:.1e}",
        r.grid_size, r.cells, r.point_forms, r.translation_forms, r.batches, r.distortion_before, r.distortion_after, r.flipped, r.integer_residual
    );
    if r.conflicts > 0 {
        println!("  warning: {} integers could not be met (determined by others at a non-integer value)", r.conflicts);
    }
    if r.flipped > 0 || r.wound_vertices > 0 {
        println!(
            "  warning: the integer-grid map folds ({} flipped triangles, {} vertices it winds around or folds the boundary at); a nearby --quads or --grid often rounds cleanly",
            r.flipped, r.wound_vertices
        );
    }
}

/// Fails when a file cannot be created at one of `paths` (missing directory,
/// or a directory in the way).
fn check_writable<'a>(paths: impl IntoIterator<Item = &'a str>) -> Result<(), Failure> {
    for path in paths {
        let parent = Path::new(path).parent().filter(|p| !p.as_os_str().is_empty());
        if let Some(dir) = parent {
            if !dir.is_dir() {
                return Err(Failure(format!("{path}: cannot write: directory {} does not exist", dir.display()), 1));
            }
        }
        if Path::new(path).is_dir() {
            return Err(Failure(format!("{path}: cannot write: is a directory"), 1));
        }
    }
    Ok(())
}

/// A mesh file read for `solve`: the file and its sibling buffers, the
/// imported mesh with its glTF source (for a drop-in export), and the
/// validated mesh.
struct InputMesh {
    main: conemap::io::InputFile,
    others: Vec<conemap::io::InputFile>,
    raw: conemap::mesh::RawMesh,
    source: Option<conemap::io::gltf::GltfSource>,
    mesh: TriMesh,
}

/// Reads and validates `file` (its first problem named when it cannot be parametrized).
fn read_input(file: &str) -> Result<InputMesh, Failure> {
    use conemap::io::{self, InputFile};
    let bytes = std::fs::read(file).map_err(|e| Failure(format!("{file}: {e}"), 1))?;
    let name = Path::new(file).file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let main = InputFile { name, bytes };
    let others = io::gltf::sibling_buffers(Path::new(file), &main).map_err(|e| Failure(format!("{file}: {e}"), 1))?;
    let io::Imported { raw, gltf: source, numbering } = io::import_file(&main, &others).map_err(|e| Failure(e.to_string(), 1))?;
    let mesh = validated(file, &raw, &numbering)?;
    Ok(InputMesh { main, others, raw, source, mesh })
}

/// Seconds per stage of `solve`.
#[derive(Default)]
struct SolveTimes {
    import: f64,
    cones: f64,
    param: f64,
    quantize: f64,
    export: f64,
}

impl SolveTimes {
    fn total(&self) -> f64 {
        self.import + self.cones + self.param + self.quantize + self.export
    }
}

/// What `solve` wrote.
struct Written<'a> {
    path: &'a str,
    format: conemap::export::Format,
    input: &'a conemap::export::ExportInput<'a>,
    options: &'a conemap::export::ExportOptions,
    bytes: usize,
}

/// The `--report` JSON of a solve: the `cones --json` fields, the map's
/// figures, the output written and the seconds per stage.
fn solve_report(
    solution: &conemap::pipeline::Solution,
    options: &ConeOptions,
    alignment: &conemap::pipeline::FeatureAlignment,
    written: &Written,
    times: &SolveTimes,
) -> serde_json::Value {
    let (mesh, placement, result) = (&*solution.mesh, &solution.placement, &solution.param);
    let mut report = cones_json(mesh, &solution.features, options, placement);
    report["inserted_vertices"] = serde_json::json!(solution.splits);
    report["refinement"] = serde_json::json!(solution.refinement);
    report["flip_refinements"] = serde_json::json!(solution.flip_refinements);
    report["feature_alignment"] = serde_json::json!(alignment);
    report["metrics"] = serde_json::json!(result.metrics);
    report["seam_edges"] = serde_json::json!(result.seam_edges.len());
    if let serde_json::Value::Object(counts) = serde_json::json!(result.counts) {
        for (key, value) in counts {
            report[key.as_str()] = value;
        }
    }
    report["realized_cones"] = serde_json::json!(result.realized_cones.len());
    let input = written.input;
    report["output"] = serde_json::json!({
        "path": written.path,
        "format": format!("{:?}", written.format).to_ascii_lowercase(),
        "vertices": input.output_vertex_count(written.options),
        "faces": mesh.n_faces(),
        "bytes": written.bytes,
        "uv_normalization": {"offset": input.uv_normalization(written.options).offset, "scale": input.uv_normalization(written.options).scale},
        "notes": input.notes(),
    });
    report["timings"] = serde_json::json!({
        "import": times.import,
        "cones": placement.timings,
        "refine": solution.refine_seconds,
        "cones_total": times.cones,
        "param": result.timings,
        "param_total": times.param,
        "quantize": times.quantize,
        "export": times.export,
        "total": times.total(),
    });
    report
}

/// The summary `solve` prints: mesh, cones, map quality, feature alignment,
/// notes, the file written and the seconds per stage.
fn print_solution(file: &str, solution: &conemap::pipeline::Solution, alignment: &conemap::pipeline::FeatureAlignment, written: &Written, times: &SolveTimes) {
    let (mesh, features, placement, result) = (&*solution.mesh, &*solution.features, &solution.placement, &solution.param);
    let m = &result.metrics;
    println!("{file}: {} vertices, {} faces, {} feature edges", mesh.n_vertices(), mesh.n_faces(), features.len());
    println!(
        "  cones: {} ({} positive, {} negative), {} boundary corners",
        placement.cones.len(),
        placement.cones.iter().filter(|c| c.k > 0).count(),
        placement.cones.iter().filter(|c| c.k < 0).count(),
        placement.boundary_corners.len()
    );
    println!(
        "  distortion {:.4} (max {:.4}), flipped triangles {} ({} fixed by repair), {} seam edges",
        m.distortion,
        m.max_distortion,
        m.flipped,
        result.counts.flips_fixed,
        result.seam_edges.len()
    );
    if alignment.requested > 0 {
        println!(
            "  feature edges: {} requested, {} on isolines (worst {:.1e} rad)",
            alignment.requested, alignment.aligned, alignment.worst_radians
        );
        for u in alignment.unaligned.iter().take(10) {
            println!("  warning: feature edge (v{}, v{}) is {:.2}° off an axis", u.vertices[0], u.vertices[1], u.degrees);
        }
    }
    if solution.splits > 0 {
        println!("  note: {}; the output is the refined mesh", refinement_note(solution.splits, &solution.refinement));
    }
    if !result.realized_cones.is_empty() {
        println!(
            "  note: {} cones and corners came out with another angle than placed (the untangled map realizes them); listed as realized",
            result.realized_cones.len()
        );
    }
    for note in written.input.notes() {
        println!("  note: {note}");
    }
    println!("  wrote {}: {} vertices, {} faces", written.path, written.input.output_vertex_count(written.options), mesh.n_faces());
    let (t_import, t_cones, t_param, t_export, total) = (times.import, times.cones, times.param, times.export, times.total());
    println!(
        "  time: import {t_import:.3} s, cones {t_cones:.3} s, parametrization {t_param:.3} s, export {t_export:.3} s, total {total:.3} s"
    );
}
