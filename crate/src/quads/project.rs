//! A quad mesh traced on one surface (a decimation of the input, say)
//! moved onto another: each vertex to the nearest point of the other
//! surface whose face is not turned against the face it was traced on, so
//! that a vertex on one side of a part thinner than the decimation's error
//! (an ear, a fin) stays on that side. Vertices on an edge both surfaces
//! share (a feature curve the decimation kept) are 0 away and stay put.

use super::extract::untangle;
use super::{QuadMesh, SurfacePoint};
use crate::features::FeatureSet;
use crate::mesh::{Nearest, NearestFace, TriMesh};
use crate::vec3::barycentric_point;

/// Moves every vertex of `quads` (located on `from`) to the nearest point
/// of `onto` on a face whose normal is within 90° of its face's on `from`
/// (the nearest point of any face where none is), and relocates it there;
/// a defect's face becomes the face of `onto` nearest to its face's
/// centroid. Then the quads that fold on `onto` are untangled there
/// ([`untangle`], `features`: those of `onto`). Returns the largest
/// distance a vertex moved onto `onto`.
pub fn project_onto(quads: &mut QuadMesh, from: &TriMesh, onto: &TriMesh, features: &FeatureSet) -> f64 {
    if onto.n_faces() == 0 {
        return 0.0;
    }
    let mut locator = NearestFace::new(onto);
    let from_normals = from.face_normals();
    let mut moved = 0.0f64;
    for (v, location) in quads.locations.iter_mut().enumerate() {
        let n = from_normals.get(location.face as usize).copied();
        let Nearest { face, bary, point, distance } = locator.nearest(quads.positions[v], n).expect("a mesh with faces");
        quads.positions[v] = point;
        *location = SurfacePoint { face, bary };
        moved = moved.max(distance);
    }
    for defect in &mut quads.defects {
        let Some(t) = from.faces().get(defect.face as usize) else { continue };
        let centroid = barycentric_point(&t.map(|v| from.position(v)), [1.0 / 3.0; 3]);
        if let Some(nearest) = locator.nearest(centroid, from_normals.get(defect.face as usize).copied()) {
            defect.face = nearest.face;
        }
    }
    untangle(onto, features, quads);
    moved
}
