//! `conemap quads`: cones, the seamless map, its integer-grid quantization
//! and the quad mesh traced on it, written as OBJ (quads) or glTF (each quad
//! as two triangles plus a LINES primitive of the quad edges).

use super::{check_writable, cone_options, grid_features, grid_option, read_input, solve_mesh, solve_options, usage, Args, Failure, ProgressLine};
use conemap::param::quantize::{GridSize, QuantizeOptions};
use conemap::pipeline::Coarse;
use conemap::quads::{check_quads, extract_quads_along, project_onto, CheckOptions, ExtractOptions, QuadReport};
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
    // A mesh much finer than its quads: traced on a decimation, moved onto the input.
    let coarse = if args.flag("--full-mesh") { None } else { Coarse::for_quads(&input.mesh, &features.all, grid) };
    let (mesh, solved_features) = match &coarse {
        Some(c) => (&c.mesh, c.grid_features(&input.mesh, &features)),
        None => (&input.mesh, features.clone()),
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
    let quantize_seconds = clock.lap();
    // On a decimation, the quads are untangled once they are on the input.
    let extract_options = ExtractOptions { untangle: coarse.is_none(), ..ExtractOptions::default() };
    let mut quads = extract_quads_along(&solution.mesh, &solution.features, &map.uv, &extract_options).map_err(|e| Failure(format!("{file}: {e}"), 1))?;
    let (dropped_features, projected) = match &coarse {
        Some(c) => (c.input_features(&input.mesh, &dropped_features), Some(project_onto(&mut quads, &solution.mesh, &input.mesh, &features.all))),
        None => (dropped_features, None),
    };
    let extract = clock.lap();
    // Every feature solved for (detected creases too), the dropped ones too,
    // on the input (or where it was solved on a refinement, on that).
    let (checked_mesh, sharp) = match &coarse {
        Some(_) => (&input.mesh, features.all.edges().collect()),
        None => (&*solution.mesh, solution.solved_edges_of(&features.all)),
    };
    let report = check_quads(checked_mesh, &quads, &CheckOptions { sharp_edges: &sharp, ..CheckOptions::default() });
    let check = clock.lap();

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
            "quantization": map.report,
            "quads": report,
            "defects": quads.defects,
            "timings": {"import": import, "solve": solve, "quantize": quantize_seconds, "extract": extract, "check": check, "write": write},
        });
        let text = serde_json::to_string_pretty(&json).map_err(|e| Failure(e.to_string(), 1))?;
        std::fs::write(path, text + "\n").map_err(|e| Failure(format!("{path}: cannot write: {e}"), 1))?;
    }
    println!("{file}: {} vertices, {} faces, {} feature edges, {} cones", input.mesh.n_vertices(), input.mesh.n_faces(), features.all.len(), solution.placement.cones.len());
    if let (Some(c), Some(moved)) = (&coarse, projected) {
        println!(
            "  traced on a decimation to {} faces ({} per quad asked; --full-mesh solves on all {}), vertices moved onto the input by at most {:.2e} ({:.3} % of the diagonal)",
            c.mesh.n_faces(),
            conemap::pipeline::COARSE_FACES_PER_QUAD,
            input.mesh.n_faces(),
            moved,
            100.0 * moved / input.mesh.bounding_diagonal()
        );
    }
    super::print_dropped_features(&features, &dropped_features);
    super::print_quantization(&map.report);
    print_quads(&report, quads.defects.len());
    println!("  wrote {out}: {} quads, {} vertices", quads.n_quads(), quads.n_vertices());
    println!(
        "  time: import {import:.3} s, cones and map {solve:.3} s, quantization {quantize_seconds:.3} s, extraction {extract:.3} s, checks {check:.3} s"
    );
    Ok(())
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
