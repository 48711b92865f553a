// The quad mesh over the surface in the 3D view: its edges as thin lines, its
// interior singular vertices as small spheres coloured by valence (3, 5,
// other), and the integer-grid checker (one square per grid cell) in place of
// the seamless map's while it is shown. The cone markers are hidden meanwhile
// (they sit on the singular vertices they cause).
import * as THREE from 'three';
import { COLORS, valenceColor } from './palette';
import type { QuadsResult } from './protocol';
import type { Viewer } from './viewer';

/** Overlay name of the singular-vertex markers in the viewer; the edges are the line layer of the same name. */
const SINGULAR = 'quad-singular';
const EDGES = 'quad-edges';

/** The quad edges `edges` (2 vertex ids each) of `positions` (xyz each) as line segments: 2 xyz points per edge. */
export function quadEdgeSegments(positions: Float32Array, edges: Uint32Array): Float32Array {
  const out = new Float32Array(edges.length * 3);
  for (let i = 0; i < edges.length; i++) {
    const v = 3 * edges[i]!;
    out[3 * i] = positions[v]!;
    out[3 * i + 1] = positions[v + 1]!;
    out[3 * i + 2] = positions[v + 2]!;
  }
  return out;
}

/** Counts of the (vertex, valence) pairs in `singular` by valence: 3, 5 and any other. */
export function valenceCounts(singular: Uint32Array): { three: number; five: number; other: number } {
  const counts = { three: 0, five: 0, other: 0 };
  for (let i = 1; i < singular.length; i += 2) {
    const v = singular[i]!;
    if (v === 3) counts.three++;
    else if (v === 5) counts.five++;
    else counts.other++;
  }
  return counts;
}

export class QuadView {
  private shown: QuadsResult | null = null;
  private edgesVisible = true;

  constructor(private readonly viewer: Viewer) {}

  /** Shows quads result `r` in place of the one shown (edges only while `setEdgesVisible(true)`, the default). */
  show(r: QuadsResult): void {
    this.shown = r;
    this.viewer.setGridUv(r.uv);
    this.viewer.setConesVisible(false);
    this.drawEdges();
    this.viewer.setOverlay(SINGULAR, this.singularMarkers(r));
  }

  /** Removes the quad mesh and goes back to the seamless map's checker and the cone markers. */
  clear(): void {
    if (!this.shown) return;
    this.shown = null;
    this.viewer.setGridUv(null);
    this.viewer.setConesVisible(true);
    this.viewer.setSegments(EDGES, new Float32Array(0), COLORS.quadEdge);
    this.viewer.setOverlay(SINGULAR, null);
  }

  /** Shows or hides the quad edges ("show quads"); the singular vertices and the grid checker stay. */
  setEdgesVisible(visible: boolean): void {
    this.edgesVisible = visible;
    this.drawEdges();
  }

  private drawEdges(): void {
    const r = this.shown;
    const seg = r && this.edgesVisible ? quadEdgeSegments(r.positions, r.edges) : new Float32Array(0);
    this.viewer.setSegments(EDGES, seg, COLORS.quadEdge, 1.25, 1);
  }

  /** The interior singular vertices of `r` as spheres (1.4 % of the mesh radius) coloured by valence; null when there are none. */
  private singularMarkers(r: QuadsResult): THREE.InstancedMesh | null {
    const n = r.singular.length / 2;
    if (n === 0) return null;
    const radius = this.viewer.radius * 0.014;
    const material = new THREE.MeshStandardMaterial({ roughness: 0.4, metalness: 0.05 });
    const markers = new THREE.InstancedMesh(new THREE.SphereGeometry(radius, 14, 10), material, n);
    const m = new THREE.Matrix4();
    const color = new THREE.Color();
    const p = r.positions;
    for (let i = 0; i < n; i++) {
      const v = 3 * r.singular[2 * i]!;
      markers.setMatrixAt(i, m.makeTranslation(p[v]!, p[v + 1]!, p[v + 2]!));
      markers.setColorAt(i, color.setHex(valenceColor(r.singular[2 * i + 1]!)));
    }
    markers.renderOrder = 6;
    return markers;
  }
}
