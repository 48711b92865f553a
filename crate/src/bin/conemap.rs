//! The conemap command-line tool. Thin: argument parsing and printing only.
//!
//! `conemap <command> [args]`; each command is one function taking the
//! arguments after its name, so later commands (`cones`, `solve`) slot into
//! [`COMMANDS`] and [`run`].

use conemap::mesh::{analyze, MeshReport};
use std::path::Path;
use std::process::ExitCode;

const USAGE: &str = "\
usage: conemap <command> [options]

commands:
  info FILE [--json]   read a mesh (.obj, .gltf, .glb) and report its figures
                       (vertices, faces, boundary, components, Euler
                       characteristic, genus) and every problem found.
                       --json prints one JSON object instead.

options:
  -h, --help           print this help

Exit status: 0 when the file was read (even if it has problems), 1 when it
could not be read or parsed, 2 for bad usage.";

/// Commands and the flags they accept.
const COMMANDS: &[(&str, &[&str])] = &[("info", &["--json"])];

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
                "info" => info(&parsed),
                _ => unreachable!("command listed in COMMANDS without a handler"),
            }
        }
    }
}

fn usage(msg: &str) -> Failure {
    Failure(format!("{msg} (try `conemap --help`)"), 2)
}

/// Positional arguments and `--flag`s of one command.
struct Args {
    positional: Vec<String>,
    flags: Vec<String>,
    help: bool,
}

impl Args {
    fn parse(args: &[String], allowed: &[&str]) -> Result<Args, Failure> {
        let mut out = Args { positional: Vec::new(), flags: Vec::new(), help: false };
        let mut only_positional = false;
        for a in args {
            if only_positional || !a.starts_with('-') || a == "-" {
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
    /// The single positional FILE argument.
    fn file(&self) -> Result<&str, Failure> {
        match self.positional.as_slice() {
            [f] => Ok(f),
            [] => Err(usage("missing FILE")),
            _ => Err(usage("expected exactly one FILE")),
        }
    }
}

fn info(args: &Args) -> Result<(), Failure> {
    let file = args.file()?;
    let raw = conemap::io::import_path(Path::new(file)).map_err(|e| Failure(e.to_string(), 1))?;
    let report = analyze(&raw);
    if args.flag("--json") {
        let json = serde_json::to_string(&report).map_err(|e| Failure(e.to_string(), 1))?;
        println!("{json}");
    } else {
        print_report(file, &report);
    }
    Ok(())
}

fn print_report(file: &str, r: &MeshReport) {
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
        for p in r.problems.iter().take(MAX_PROBLEMS) {
            println!("    {p}");
        }
        if r.problems.len() > MAX_PROBLEMS {
            println!("    … and {} more (use --json for all)", r.problems.len() - MAX_PROBLEMS);
        }
    }
}
