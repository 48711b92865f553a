//! Feature-edge files: the edges as pairs of end positions, so that a list
//! does not depend on vertex numbering. Two forms are read: the CLI's
//! `--features` file `{"edges": [[[x, y, z], [x, y, z]], …]}` and the page's
//! JSON report `{"features": {"positions": [[[x, y, z], [x, y, z]], …]}}`.

use serde::Deserialize;

/// One edge: the positions of its two ends.
pub type EdgeEnds = [[f64; 3]; 2];

#[derive(Deserialize)]
struct CliFile {
    edges: Vec<EdgeEnds>,
}

#[derive(Deserialize)]
struct ReportFeatures {
    positions: Vec<EdgeEnds>,
}

#[derive(Deserialize)]
struct ReportFile {
    features: ReportFeatures,
}

/// The feature edges of a features file or JSON report (`text`), or a
/// one-line message saying what the file lacks.
pub fn parse_feature_edges(text: &str) -> Result<Vec<EdgeEnds>, String> {
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| format!("not a JSON file ({e})"))?;
    if value.get("features").is_some() {
        return ReportFile::deserialize(&value)
            .map(|r| r.features.positions)
            .map_err(|e| format!("the report's \"features\" need \"positions\": [[[x, y, z], [x, y, z]], …] ({e})"));
    }
    CliFile::deserialize(&value)
        .map(|f| f.edges)
        .map_err(|e| format!("expected {{\"edges\": [[[x, y, z], [x, y, z]], …]}} or a conemap JSON report ({e})"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_both_forms_and_says_what_is_wrong() {
        let edge = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        assert_eq!(parse_feature_edges(r#"{"edges": [[[0,0,0],[1,0,0]]]}"#).unwrap(), vec![edge]);
        let report = r#"{"settings": {}, "features": {"edges": [3], "positions": [[[0,0,0],[1,0,0]]], "boundary_edges": 0}}"#;
        assert_eq!(parse_feature_edges(report).unwrap(), vec![edge]);
        assert!(parse_feature_edges("{").unwrap_err().starts_with("not a JSON file"));
        assert!(parse_feature_edges(r#"{"edges": [1, 2]}"#).unwrap_err().starts_with("expected {\"edges\""));
        assert!(parse_feature_edges(r#"{"features": {"edges": [1]}}"#).unwrap_err().contains("\"positions\""));
    }
}
