//! `conemap quads`: cones, the seamless map, its integer-grid quantization
//! and the quad mesh traced on it, written as OBJ (quads) or glTF (each quad
//! as two triangles plus a LINES primitive of the quad edges).

use super::{check_writable, cone_options, grid_features, grid_option, read_input, solve_mesh, solve_options, usage, Args, Failure, ProgressLine};
use conemap::param::quantize::{GridSize, QuantizeOptions};
use conemap::features::FeatureSet;
use conemap::mesh::TriMesh;
use conemap::pipeline::{Coarse, GridFeatures, COARSE_FACES_PER_QUAD};
use conemap::quads::{check_quads, extract_quads_along, project_onto, CheckOptions, ExtractOptions, QuadMesh, QuadReport};
use std::path::Path;

/// Quads asked for when neither `--quad-size` nor `--quads` is given.
pub const DEFAULT_QUADS: usize = 3000;

pub fn quads_command(args: &Args) -> Result<(), Failure> {
    use conemap::export::quads::{write_quad_glb, write_quad_obj};
    let file = args.file()?;
    let out = args.value("-o").or_else(|| args.value("--output")).ok_or_else(|| usage("quads needs -o OUT"))?;
    let lower = out.to_ascii_lowercase();
    let obj = lower.ends_with(".obj");
    if !obj && !lower.ends_with(".glb") {
        return Err(usage(&format!("{out}: unknown quad-mesh format (use .obj or .glb)")));
    }
    cone_options(args)?;
    let grid = grid_option(args, "--quad-size")?.unwrap_or(GridSize::Quads(DEFAULT_QUADS));
    check_writable([Some(out), args.value("--report")].into_iter().flatten())?;

    let mut clock = conemap::clock::Stopwatch::start();
    let input = read_input(file)?;
    let import = clock.lap();
    let features = grid_features(args, &input.mesh)?;
    // A mesh much finer than its quads: traced on a decimation, moved onto
    // the input; where those quads fold, again on a decimation twice as
    // fine (or the input), keeping the better.
    let decimate = |faces_per_quad: f64| if args.flag("--full-mesh") { None } else { Coarse::for_quads(&input.mesh, &features.all, grid, faces_per_quad) };
    let detect = clock.lap();
    let first = decimate(COARSE_FACES_PER_QUAD);
    let decimated = first.is_some();
    let mut decimation = clock.lap();
    // Where the decimation's solve fails (its map folds, say), the input's.
    let mut traced = match trace(args, file, &input.mesh, &features, &features.all, grid, first) {
        Err(_) if decimated => trace(args, file, &input.mesh, &features, &features.all, grid, None)?,
        traced => traced?,
    };
    let mut retried_on = None;
    if traced.coarse.is_some() && traced.folds() > 0 {
        // With the features the first kept, none dropped again: one solve
        // and rounding (the creases of an organic part folding the map
        // cost several: cow subdivided twice at 3 000 quads, 400 s).
        let kept = GridFeatures::asked(&input.mesh, features.all.without(&traced.dropped_features));
        clock.lap();
        let finer = decimate(2.0 * COARSE_FACES_PER_QUAD);
        decimation += clock.lap();
        retried_on = Some(if finer.is_some() { "a decimation twice as fine" } else { "the input" });
        if let Ok(mut again) = trace(args, file, &input.mesh, &kept, &features.all, grid, finer) {
            again.dropped_features.union(&traced.dropped_features);
            traced = Traced::better(traced, again);
        }
    }
    let Traced { solution, map, dropped_features, quads, report, coarse, projected, seconds: [solve, quantize_seconds, extract, check], attempts } = traced;
    clock.lap();

    let data = if obj {
        let stem = Path::new(file).file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        write_quad_obj(&quads, &format!("quad mesh of {stem}: {} quads, grid cell {}", quads.n_quads(), map.report.grid_size)).into_bytes()
    } else {
        write_quad_glb(&quads)
    };
    std::fs::write(out, &data).map_err(|e| Failure(format!("{out}: cannot write: {e}"), 1))?;
    let write = clock.lap();

    if let Some(path) = args.value("--report") {
        let json = serde_json::json!({
            "input": file,
            "output": {"path": out, "bytes": data.len()},
            "cones": solution.placement.cones.len(),
            "dropped_feature_edges": dropped_features.len(),
            "detected_feature_edges": features.detected.len(),
            "distortion_seamless": solution.param.metrics.distortion,
            "decimated": coarse.as_ref().map(|c| serde_json::json!({"faces": c.mesh.n_faces(), "vertices": c.mesh.n_vertices(), "largest_projection": projected})),
            "attempts": attempts,
            "quantization": map.report,
            "quads": report,
            "defects": quads.defects,
            "timings": {"import": import, "features": detect, "decimate": decimation, "solve": solve, "quantize": quantize_seconds, "extract": extract, "check": check, "write": write},
        });
        let text = serde_json::to_string_pretty(&json).map_err(|e| Failure(e.to_string(), 1))?;
        std::fs::write(path, text + "\n").map_err(|e| Failure(format!("{path}: cannot write: {e}"), 1))?;
    }
    println!("{file}: {} vertices, {} faces, {} feature edges, {} cones", input.mesh.n_vertices(), input.mesh.n_faces(), features.all.len(), solution.placement.cones.len());
    if let (Some(c), Some(moved)) = (&coarse, projected) {
        println!(
            "  traced on a decimation to {} faces (--full-mesh: on all {}), vertices moved onto the input by at most {:.2e} ({:.3} % of the diagonal)",
            c.mesh.n_faces(),
            input.mesh.n_faces(),
            moved,
            100.0 * moved / input.mesh.bounding_diagonal()
        );
    }
    if let Some(on) = retried_on {
        println!("  the quads of the decimation folded: traced again on {on}, the better kept");
    } else if decimated && coarse.is_none() {
        println!("  the map of the decimation could not be solved: traced on the input");
    }
    super::print_dropped_features(&features, &dropped_features);
    super::print_quantization(&map.report);
    print_quads(&report, quads.defects.len());
    println!("  wrote {out}: {} quads, {} vertices", quads.n_quads(), quads.n_vertices());
    println!(
        "  time: import {import:.3} s, features {detect:.3} s, decimation {decimation:.3} s, cones and map {solve:.3} s, quantization {quantize_seconds:.3} s, extraction {extract:.3} s, checks {check:.3} s"
    );
    Ok(())
}

/// The quads of `input` traced on `coarse` (a decimation of it) or on
/// `input` itself, with what they took.
struct Traced {
    solution: conemap::pipeline::Solution<'static>,
    map: conemap::param::quantize::IntegerGridMap,
    /// Feature edges of the input the map was solved without.
    dropped_features: FeatureSet,
    quads: QuadMesh,
    report: QuadReport,
    coarse: Option<Coarse>,
    /// How far the quads' vertices moved onto the input (decimation only).
    projected: Option<f64>,
    /// Cones and map, quantization, extraction, checks (seconds), summed
    /// over the attempts.
    seconds: [f64; 4],
    attempts: usize,
}

impl Traced {
    /// Defect places, flipped and degenerate quads.
    fn folds(&self) -> usize {
        self.report.defects + self.report.flipped_quads + self.report.degenerate_quads
    }

    /// The one with fewer folds, then nearer the input (ties: `a`), its
    /// seconds and attempts those of both.
    fn better(a: Traced, b: Traced) -> Traced {
        let distance = |t: &Traced| t.report.distance_input_to_quads_relative.unwrap_or(0.0).max(t.report.distance_quads_to_input_relative.unwrap_or(0.0));
        let (seconds, attempts) = (std::array::from_fn(|k| a.seconds[k] + b.seconds[k]), a.attempts + b.attempts);
        let mut kept = if (b.folds(), distance(&b)) < (a.folds(), distance(&a)) { b } else { a };
        (kept.seconds, kept.attempts) = (seconds, attempts);
        kept
    }
}

/// The cones, map, integer-grid map and quads of `input` (with `features`,
/// for `grid`) solved on `coarse` and moved onto `input`, or solved on
/// `input` where `coarse` is `None`, and their figures against `input`
/// (`sharp`: its feature edges checked).
fn trace(args: &Args, file: &str, input: &TriMesh, features: &GridFeatures, sharp: &FeatureSet, grid: GridSize, coarse: Option<Coarse>) -> Result<Traced, Failure> {
    let mut clock = conemap::clock::Stopwatch::start();
    let (mesh, solved_features) = match &coarse {
        Some(c) => (&c.mesh, c.grid_features(input, features)),
        None => (input, features.clone()),
    };
    let max_edge = conemap::pipeline::RefineOptions::for_quads(mesh, grid).max_edge_length;
    let options = solve_options(args, mesh, max_edge)?.for_quads(mesh, grid);
    let solution = solve_mesh(args, file, mesh, &solved_features.all, &options)?;
    let solve = clock.lap();
    // Solves again without the feature curves finer than the grid where
    // they fold the map (counted as quantization time).
    let bar = ProgressLine::new(args);
    let long_edges = conemap::pipeline::LongEdges::RefineFirst;
    let mapped = conemap::pipeline::grid_map(mesh, &solved_features, &options, solution, grid, &QuantizeOptions::default(), long_edges, &mut |p| bar.solve(p), &mut |_, _| {});
    bar.finish();
    let conemap::pipeline::GridMapped { solution, map, dropped_features, .. } = mapped.map_err(|e| Failure(format!("{file}: {e}"), 1))?;
    let quantize = clock.lap();
    // On a decimation, the quads are untangled once they are on the input.
    let extract_options = ExtractOptions { untangle: coarse.is_none(), ..ExtractOptions::default() };
    let mut quads = extract_quads_along(&solution.mesh, &solution.features, &map.uv, &extract_options).map_err(|e| Failure(format!("{file}: {e}"), 1))?;
    let (dropped_features, projected) = match &coarse {
        Some(c) => (c.input_features(input, &dropped_features), Some(project_onto(&mut quads, &solution.mesh, input, sharp))),
        None => (dropped_features, None),
    };
    let extract = clock.lap();
    // Every feature solved for (detected creases too), the dropped ones too,
    // on the input (or where it was solved on a refinement, on that).
    let (checked_mesh, sharp) = match &coarse {
        Some(_) => (input, sharp.edges().collect()),
        None => (&*solution.mesh, solution.solved_edges_of(sharp)),
    };
    let report = check_quads(checked_mesh, &quads, &CheckOptions { sharp_edges: &sharp, ..CheckOptions::default() });
    let check = clock.lap();
    Ok(Traced { solution, map, dropped_features, quads, report, coarse, projected, seconds: [solve, quantize, extract, check], attempts: 1 })
}

/// The summary of a quad mesh's figures.
fn print_quads(r: &QuadReport, defects: usize) {
    let singular: Vec<String> = r.valence_histogram.interior.iter().filter(|(&v, _)| v != 4).map(|(v, n)| format!("{n} of valence {v}")).collect();
    println!(
        "  quads: {} (Euler characteristic {}, {} boundary loops), singular vertices: {}",
        r.quads,
        r.euler_characteristic,
        r.boundary_loops,
        if singular.is_empty() { "none".to_string() } else { singular.join(", ") }
    );
    println!(
        "  corner angles: mean deviation {:.1}°, max {:.1}°, {:.1} % of quads within 45-135°; flipped quads {}, degenerate {}, non-manifold edges {}",
        r.angle_mean_deviation,
        r.angle_max_deviation,
        100.0 * r.fraction_corners_45_135,
        r.flipped_quads,
        r.degenerate_quads,
        r.non_manifold_edges
    );
    if defects > 0 {
        println!("  warning: {defects} places where the map is not a valid integer-grid map (see the report's defects)");
    }
}
