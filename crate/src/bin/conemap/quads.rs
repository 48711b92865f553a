//! `conemap quads`: cones, the seamless map, its integer-grid quantization
//! and the quad mesh traced on it, written as OBJ (quads) or glTF (each quad
//! as two triangles plus a LINES primitive of the quad edges).

use super::{check_writable, cone_options, grid_features, grid_option, read_input, solve_options, usage, Args, Failure, ProgressLine};
use conemap::param::quantize::{GridSize, QuantizeOptions};
use conemap::pipeline::{Attempts, QuadOptions, QuadStage, QuadTimings, TracedQuads};
use conemap::quads::QuadReport;
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
    let detect = clock.lap();
    let options = QuadOptions { solve: solve_options(args, &input.mesh, None)?, quantize: QuantizeOptions::default(), full_mesh: args.flag("--full-mesh") };
    let mut stage = QuadStage::new(features.clone(), options);
    let bar = ProgressLine::new(args);
    let traced = stage.quads(&input.mesh, grid, &mut |p| bar.quads(p));
    bar.finish();
    let TracedQuads { solution, map, dropped_features, quads, report, decimation, attempts, traced, timings, .. } = traced.map_err(|e| Failure(format!("{file}: {e}"), 1))?;
    clock.lap();

    let data = if obj {
        let stem = Path::new(file).file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        write_quad_obj(&quads, &format!("quad mesh of {stem}: {} quads, grid cell {}", quads.n_quads(), map.report.grid_size)).into_bytes()
    } else {
        write_quad_glb(&quads)
    };
    std::fs::write(out, &data).map_err(|e| Failure(format!("{out}: cannot write: {e}"), 1))?;
    let write = clock.lap();

    let QuadTimings { decimate, solve, quantize, extract, check } = timings;
    if let Some(path) = args.value("--report") {
        let json = serde_json::json!({
            "input": file,
            "output": {"path": out, "bytes": data.len()},
            "cones": solution.placement.cones.len(),
            "dropped_feature_edges": dropped_features.len(),
            "detected_feature_edges": features.detected.len(),
            "distortion_seamless": solution.param.metrics.distortion,
            "decimated": decimation,
            "attempts": traced,
            "quantization": map.report,
            "quads": report,
            "defects": quads.defects,
            "timings": {"import": import, "features": detect, "decimate": decimate, "solve": solve, "quantize": quantize, "extract": extract, "check": check, "write": write},
        });
        let text = serde_json::to_string_pretty(&json).map_err(|e| Failure(e.to_string(), 1))?;
        std::fs::write(path, text + "\n").map_err(|e| Failure(format!("{path}: cannot write: {e}"), 1))?;
    }
    println!("{file}: {} vertices, {} faces, {} feature edges, {} cones", input.mesh.n_vertices(), input.mesh.n_faces(), features.all.len(), solution.placement.cones.len());
    if let Some(d) = &decimation {
        println!(
            "  traced on a decimation to {} faces (--full-mesh: on all {}), vertices moved onto the input by at most {:.2e} ({:.3} % of the diagonal)",
            d.faces,
            input.mesh.n_faces(),
            d.largest_projection,
            100.0 * d.largest_projection / input.mesh.bounding_diagonal()
        );
    }
    match attempts {
        Attempts::Retried { on_input } => {
            let on = if on_input { "the input" } else { "a decimation twice as fine" };
            println!("  the quads of the decimation folded: traced again on {on}, the better kept");
        }
        Attempts::DecimationUnsolved => println!("  the map of the decimation could not be solved: traced on the input"),
        Attempts::Once => {}
    }
    super::print_dropped_features(&features, &dropped_features);
    super::print_quantization(&map.report);
    print_quads(&report, quads.defects.len());
    println!("  wrote {out}: {} quads, {} vertices", quads.n_quads(), quads.n_vertices());
    println!(
        "  time: import {import:.3} s, features {detect:.3} s, decimation {decimate:.3} s, cones and map {solve:.3} s, quantization {quantize:.3} s, extraction {extract:.3} s, checks {check:.3} s"
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
