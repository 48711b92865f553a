// Plain words for the jargon of the figures tables (mesh, result, quads):
// shown as the tooltip of a row's label. Keys are the labels as shown.

export const GLOSSARY: Readonly<Record<string, string>> = {
  'Euler characteristic': 'χ = vertices − edges + faces: 2 for a closed surface without handles, 2 − 2 × (handles) − (holes) in general.',
  Genus: 'Number of handles (a sphere 0, a torus 1), per connected part; — where a part is not a clean surface.',
  'Boundary loops': 'Open borders (holes) of the surface.',
  'Non-manifold edges': 'Edges shared by more than two faces: the surface is not a clean sheet there, and cannot be parametrized.',
  'Merged vertices': 'Vertices at exactly the same position as another, joined into one on import.',
  Features: 'Edges the map lines up with (u or v constant along them).',
  Cones: 'Vertices where the map has a singularity: k = +1 (3 quads meet there), k = −1 (5 quads meet), |k| > 1 rarer. k counts quarter turns of curvature.',
  'Boundary corners': 'Points where the border turns by a multiple of 90° in the map (the corners of the layout).',
  'Σk (cones + corners)': 'The curvature of all cones and corners in quarter turns. It must equal 4χ (4 × Euler characteristic) — Gauss–Bonnet; a check of the solve.',
  'Σk (cones)': 'The curvature of all cones in quarter turns; with a free boundary, the border takes the rest of 4χ.',
  Energy: 'How much the placed cones still bend the field: the smoothness-weighted size of the scale correction φ (smaller is smoother).',
  'φ rms': 'Root-mean-square of φ, the log of how much the map scales the surface locally: 0 = no size change anywhere.',
  'Rounding rounds': 'Rounds the solver took to make every cone index a whole number.',
  Distortion: 'Mean stretch of the map per face (0 = no stretch): how far each triangle is from its shape in 3D.',
  'Faces < 0.2 / < 0.3': 'Share of the faces stretched by less than 0.2 and less than 0.3 (higher is better).',
  'Flipped faces': 'Faces turned over in the map (should be 0).',
  'Seam length': 'Total length of the cuts the map needs, in the mesh\'s own length units.',
  'Seam residual (angle / length)': 'How far the two sides of every cut fail to match (radians / relative length): 0 means seamless.',
  'Alignment residual': 'How far the feature edges are from lying exactly on u or v constant lines (0 = exact).',
  'Quad edge length': 'Side of one grid cell, in the mesh\'s own length units.',
  'Singular vertices': 'Quad-mesh vertices where not 4 quads meet (3 or 5, from cones of k = +1 and −1).',
};
