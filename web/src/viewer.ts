// The three.js view: the mesh (flat shaded, or textured with a checkerboard or a
// distortion heat map through the UVs), an optional edge overlay, feature /
// boundary / seam lines drawn thick on top, cones and boundary corners, named
// overlays (the quad mesh, see quad-view.ts), picking of edges and vertices.
// Renders on demand (see render-loop.ts), not continuously.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { LineMaterial } from 'three/examples/jsm/lines/LineMaterial.js';
import { LineSegments2 } from 'three/examples/jsm/lines/LineSegments2.js';
import { LineSegmentsGeometry } from 'three/examples/jsm/lines/LineSegmentsGeometry.js';
import { COLORS, checkerTexture, coneColor, gridCheckerUv } from './palette';
import type { Cone } from './protocol';
import { localEdgeLengths, markerRadius } from './marker-size';
import { RenderLoop, createRenderer } from './render-loop';
import { cornerPositions, edgeSegments } from './solve-view';

export interface MeshData {
  positions: Float32Array;
  indices: Uint32Array;
  edges: Uint32Array | null;
}

export type SurfaceMode = 'shaded' | 'checker' | 'distortion';

/** A solve's surface for the 3D view: positions and checker-scaled UVs per face corner, optional rgb per corner. */
export interface UvSurface {
  positions: Float32Array;
  uv: Float32Array;
  colors: Float32Array | null;
}

export interface Pick {
  face: number;
  /** Nearest of the face's 3 sides in screen space (0..2) and its distance in CSS px. */
  side: number;
  sideDistance: number;
  /** Nearest of the face's 3 corners (vertex id) and its distance in CSS px. */
  vertex: number;
  vertexDistance: number;
  point: THREE.Vector3;
}

export class Viewer {
  private readonly renderer: THREE.WebGLRenderer;
  private readonly scene = new THREE.Scene();
  readonly camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
  private readonly controls: OrbitControls;
  private readonly group = new THREE.Group();
  private mesh: THREE.Mesh | null = null;
  private data: MeshData | null = null;
  private wire: THREE.LineSegments | null = null;
  private wireVisible = true;
  private readonly lines = new Map<string, LineSegments2>();
  private readonly lineMaterials: LineMaterial[] = [];
  private markers = new THREE.Group();
  private anchor: THREE.Mesh | null = null;
  private problemMarkers: THREE.InstancedMesh | null = null;
  private hover: THREE.Mesh | null = null;
  private uvMesh: THREE.Mesh | null = null;
  /** The checker UVs of the UV surface, kept while the integer-grid UVs replace them (`setGridUv`). */
  private surfaceUv: Float32Array | null = null;
  private gridUvShown = false;
  private readonly overlays = new Map<string, THREE.Object3D>();
  private mode: SurfaceMode = 'shaded';
  private checker: THREE.Texture | null = null;
  private readonly raycaster = new THREE.Raycaster();
  /** Draws the scene on request (see `RenderLoop`). */
  readonly loop: RenderLoop;

  constructor(private readonly container: HTMLElement) {
    this.renderer = createRenderer(container, 'canvas');
    this.loop = new RenderLoop(this.renderer, this.scene, this.camera);

    this.scene.background = new THREE.Color(0x2b313b);
    this.scene.add(new THREE.HemisphereLight(0xf2f5ff, 0x3a3f48, 1.6));
    const key = new THREE.DirectionalLight(0xffffff, 1.8);
    key.position.set(0.6, 1, 1.2);
    this.camera.add(key); // the key light follows the view
    this.scene.add(this.camera, this.group);
    this.group.add(this.markers);

    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.loop.request());

    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  get canvas(): HTMLCanvasElement {
    return this.renderer.domElement;
  }

  get hasMesh(): boolean {
    return this.mesh !== null;
  }

  /** Bounding-sphere radius of the mesh (1 when none). */
  get radius(): number {
    return this.mesh?.geometry.boundingSphere?.radius || 1;
  }

  /** Replaces the shown mesh and frames the camera to it. */
  show(data: MeshData): void {
    this.clear();
    this.data = data;
    const geometry = new THREE.BufferGeometry();
    const position = new THREE.BufferAttribute(data.positions, 3);
    geometry.setAttribute('position', position);
    geometry.setIndex(new THREE.BufferAttribute(data.indices, 1));
    geometry.computeBoundingSphere();
    geometry.computeBoundingBox();
    this.mesh = new THREE.Mesh(geometry, this.surfaceMaterial());
    this.group.add(this.mesh);

    if (data.edges) {
      const lines = new THREE.BufferGeometry();
      lines.setAttribute('position', position); // shares the vertex buffer
      lines.setIndex(new THREE.BufferAttribute(data.edges, 1));
      lines.boundingSphere = geometry.boundingSphere;
      const lineMaterial = new THREE.LineBasicMaterial({ color: 0x1a2130, transparent: true, opacity: 0.28 });
      this.wire = new THREE.LineSegments(lines, lineMaterial);
      this.wire.visible = this.wireVisible;
      this.group.add(this.wire);
    }
    this.frame();
  }

  private surfaceMaterial(): THREE.Material {
    const common = {
      side: THREE.DoubleSide,
      // Push faces back so the edge overlay and the feature lines are not z-fighting.
      polygonOffset: true,
      polygonOffsetFactor: 3,
      polygonOffsetUnits: 3,
    };
    if (this.mode === 'checker' && this.uvMesh) {
      this.checker ??= checkerTexture();
      return new THREE.MeshStandardMaterial({ ...common, map: this.checker, roughness: 0.8, metalness: 0, flatShading: true });
    }
    if (this.mode === 'distortion' && this.uvMesh?.geometry.getAttribute('color')) {
      return new THREE.MeshStandardMaterial({ ...common, vertexColors: true, roughness: 0.85, metalness: 0, flatShading: true });
    }
    return new THREE.MeshStandardMaterial({ ...common, color: 0xc9d2de, roughness: 0.75, metalness: 0.05, flatShading: true });
  }

  /**
   * UV results: a face-corner geometry (`surface.positions`, xyz per corner)
   * carrying `surface.uv` (already scaled for the checker) and, when given,
   * per-face distortion colours (rgb per corner); the arrays are used as they
   * are (not copied). Null goes back to the plain mesh.
   */
  setUvSurface(surface: UvSurface | null): void {
    if (!surface && !this.uvMesh) return; // nothing shown, nothing to draw again
    if (this.uvMesh) {
      this.group.remove(this.uvMesh);
      this.uvMesh.geometry.dispose();
      (this.uvMesh.material as THREE.Material).dispose();
      this.uvMesh = null;
    }
    if (this.mesh) this.mesh.visible = true;
    this.surfaceUv = null;
    this.gridUvShown = false;
    if (surface && this.data && this.mesh) {
      this.surfaceUv = surface.uv;
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(surface.positions, 3));
      g.setAttribute('uv', new THREE.BufferAttribute(surface.uv, 2));
      if (surface.colors) g.setAttribute('color', new THREE.BufferAttribute(surface.colors, 3));
      g.boundingSphere = this.mesh.geometry.boundingSphere;
      this.uvMesh = new THREE.Mesh(g, new THREE.MeshBasicMaterial());
      this.group.add(this.uvMesh);
    }
    this.applyMode();
  }

  /**
   * Checker mode draws `uv` (grid units, 2 per face corner of the UV surface)
   * one square per unit instead of the surface's own checker UVs; null goes
   * back to those. Ignored without a UV surface or when the lengths differ.
   * A new UV surface starts with its own UVs.
   */
  setGridUv(uv: Float32Array | null): void {
    if (!this.uvMesh || !this.surfaceUv || (uv && uv.length !== this.surfaceUv.length)) return;
    const shown = uv ? gridCheckerUv(uv) : this.surfaceUv;
    this.uvMesh.geometry.setAttribute('uv', new THREE.BufferAttribute(shown, 2));
    this.gridUvShown = uv !== null;
    this.loop.request();
  }

  /** True while checker mode draws integer-grid UVs (see `setGridUv`). */
  get showsGridUv(): boolean {
    return this.gridUvShown;
  }

  /** Shows or hides the cone and boundary-corner markers (they would cover the quad mesh's singular vertices). */
  setConesVisible(visible: boolean): void {
    this.markers.visible = visible;
    this.loop.request();
  }

  /**
   * Puts `object` in the scene as overlay `name` (in mesh coordinates),
   * replacing and disposing the one shown under that name (its geometries
   * and materials); null removes it.
   */
  setOverlay(name: string, object: THREE.Object3D | null): void {
    const old = this.overlays.get(name);
    if (old) {
      this.group.remove(old);
      old.traverse((o) => {
        const m = o as THREE.Mesh;
        m.geometry?.dispose();
        for (const mat of [m.material ?? []].flat()) mat.dispose();
      });
      this.overlays.delete(name);
    }
    if (object) {
      this.overlays.set(name, object);
      this.group.add(object);
    }
    if (old || object) this.loop.request();
  }

  setSurfaceMode(mode: SurfaceMode): void {
    this.mode = mode;
    this.applyMode();
  }

  private applyMode(): void {
    if (!this.mesh) return;
    const textured = this.mode !== 'shaded' && this.uvMesh !== null;
    if (this.uvMesh) {
      (this.uvMesh.material as THREE.Material).dispose();
      this.uvMesh.material = this.surfaceMaterial();
      this.uvMesh.visible = textured;
    }
    this.mesh.visible = !textured;
    this.loop.request();
  }

  get wireframeAvailable(): boolean {
    return this.wire !== null;
  }

  setWireframe(visible: boolean): void {
    this.wireVisible = visible;
    if (this.wire) this.wire.visible = visible;
    this.loop.request();
  }

  /**
   * Draws `edgeIds` of `edges` as thick lines (a named layer: 'features',
   * 'boundary', 'seams'); an empty list hides the layer.
   */
  setLines(name: string, edges: Uint32Array, edgeIds: ArrayLike<number>, color: number, width = 3, order = 0): void {
    const seg = this.data && edgeIds.length ? edgeSegments(this.data.positions, edges, edgeIds) : new Float32Array(0);
    this.setSegments(name, seg, color, width, order);
  }

  /** Like `setLines` with the segments given (2 xyz points each, mesh coordinates; used as is). */
  setSegments(name: string, seg: Float32Array, color: number, width = 3, order = 0): void {
    const old = this.lines.get(name);
    if (old) {
      this.group.remove(old);
      old.geometry.dispose();
      this.lines.delete(name);
    }
    if (!this.data || seg.length === 0) {
      if (old) this.loop.request();
      return;
    }
    const g = new LineSegmentsGeometry();
    g.setPositions(seg);
    let material = this.lineMaterials.find((m) => m.userData['name'] === name);
    if (!material) {
      // Depth-tested against the (offset-back) surface, and pulled forward a little
      // themselves, so the lines sit on top of the faces they lie on but hide behind the mesh.
      material = new LineMaterial({
        color, linewidth: width, worldUnits: false, depthTest: true,
        polygonOffset: true, polygonOffsetFactor: -2, polygonOffsetUnits: -6,
      });
      material.userData['name'] = name;
      material.resolution.set(this.container.clientWidth || 1, this.container.clientHeight || 1);
      this.lineMaterials.push(material);
    }
    material.color.setHex(color);
    material.linewidth = width;
    const lines = new LineSegments2(g, material);
    lines.renderOrder = 2 + order;
    this.lines.set(name, lines);
    this.group.add(lines);
    this.loop.request();
  }

  /**
   * Cones as spheres coloured by index; boundary corners as small cubes. Each
   * marker is sized by the edges around its vertex (see `markerRadius`), so
   * that dense cones stay apart.
   */
  setCones(cones: Cone[], corners: Cone[]): void {
    if (cones.length === 0 && corners.length === 0 && this.markers.children.length === 0) return;
    for (const child of [...this.markers.children]) {
      this.markers.remove(child);
      const m = child as THREE.InstancedMesh;
      m.geometry.dispose();
      (m.material as THREE.Material).dispose();
    }
    const box = this.mesh?.geometry.boundingBox;
    const diagonal = box ? box.max.distanceTo(box.min) : 1;
    const place = (list: Cone[], geometry: THREE.BufferGeometry, colorOf: (c: Cone) => number): void => {
      if (list.length === 0) return;
      const local = this.data ? localEdgeLengths(this.data.positions, this.data.indices, list.map((c) => c.vertex)) : null;
      const material = new THREE.MeshStandardMaterial({ roughness: 0.35, metalness: 0.1 });
      const im = new THREE.InstancedMesh(geometry, material, list.length);
      const m = new THREE.Matrix4();
      const color = new THREE.Color();
      list.forEach((c, i) => {
        const r = markerRadius(local?.[i] ?? NaN, diagonal);
        m.makeScale(r, r, r).setPosition(c.position[0], c.position[1], c.position[2]);
        im.setMatrixAt(i, m);
        im.setColorAt(i, color.setHex(colorOf(c)));
      });
      im.computeBoundingSphere();
      im.renderOrder = 5;
      this.markers.add(im);
    };
    // Unit shapes, scaled per marker: a sphere of radius 1, a cube of side 1.7.
    place(cones, new THREE.SphereGeometry(1, 20, 14), (c) => coneColor(c.k));
    place(corners, new THREE.BoxGeometry(1.7, 1.7, 1.7), () => COLORS.corner);
    this.loop.request();
  }

  /** Marks the first vertex of a Shift-click path (null removes the marker). */
  setAnchor(vertex: number | null): void {
    if (this.anchor) {
      this.group.remove(this.anchor);
      this.anchor.geometry.dispose();
      this.anchor = null;
    }
    if (vertex !== null && this.data) {
      const box = this.mesh?.geometry.boundingBox;
      const r = (box ? box.max.distanceTo(box.min) : 1) * 0.006;
      this.anchor = new THREE.Mesh(new THREE.SphereGeometry(r, 16, 12), new THREE.MeshBasicMaterial({ color: COLORS.anchor, depthTest: false }));
      const p = this.data.positions;
      this.anchor.position.set(p[3 * vertex]!, p[3 * vertex + 1]!, p[3 * vertex + 2]!);
      this.anchor.renderOrder = 10;
      this.group.add(this.anchor);
    }
    this.loop.request();
  }

  /**
   * Marks the vertices where a solve failed (spheres in COLORS.problem, drawn
   * over the mesh so that they show through it); an empty list removes them.
   */
  setProblemVertices(vertices: ArrayLike<number>): void {
    if (this.problemMarkers) {
      this.group.remove(this.problemMarkers);
      this.problemMarkers.geometry.dispose();
      (this.problemMarkers.material as THREE.Material).dispose();
      this.problemMarkers = null;
    }
    const n = this.data ? this.data.positions.length / 3 : 0;
    const ids = Array.from(vertices).filter((v) => v < n);
    if (ids.length > 0 && this.data) {
      const box = this.mesh?.geometry.boundingBox;
      const r = (box ? box.max.distanceTo(box.min) : 1) * 0.007;
      const material = new THREE.MeshBasicMaterial({ color: COLORS.problem, depthTest: false, transparent: true, opacity: 0.9 });
      const im = new THREE.InstancedMesh(new THREE.SphereGeometry(r, 16, 12), material, ids.length);
      const p = this.data.positions;
      const m = new THREE.Matrix4();
      ids.forEach((v, i) => im.setMatrixAt(i, m.makeTranslation(p[3 * v]!, p[3 * v + 1]!, p[3 * v + 2]!)));
      im.renderOrder = 11;
      this.problemMarkers = im;
      this.group.add(im);
    }
    this.loop.request();
  }

  /** Highlights one face (hover sync with the UV view); null removes it. */
  setHoverFace(face: number | null): void {
    if (face === null || !this.data) {
      if (this.hover) this.hover.visible = false;
      this.loop.request();
      return;
    }
    if (!this.hover) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(9), 3));
      this.hover = new THREE.Mesh(g, new THREE.MeshBasicMaterial({ color: COLORS.hover, side: THREE.DoubleSide, depthTest: false, transparent: true, opacity: 0.85 }));
      this.hover.renderOrder = 9;
      this.group.add(this.hover);
    }
    const attr = this.hover.geometry.getAttribute('position') as THREE.BufferAttribute;
    const { positions, indices } = this.data;
    for (let k = 0; k < 3; k++) {
      const v = indices[3 * face + k]!;
      attr.setXYZ(k, positions[3 * v]!, positions[3 * v + 1]!, positions[3 * v + 2]!);
    }
    attr.needsUpdate = true;
    this.hover.geometry.computeBoundingSphere();
    this.hover.visible = true;
    this.loop.request();
  }

  /**
   * Highlights the faces `faces` (ids of the shown mesh; the selected chart)
   * over the surface; null or none removes the highlight. Returns the faces
   * highlighted.
   */
  setSelectedFaces(faces: Uint32Array | null): number {
    const n = this.data ? this.data.indices.length / 3 : 0;
    const ids = faces ? Array.from(faces).filter((f) => f < n) : [];
    if (ids.length === 0 || !this.data) {
      this.setOverlay('selection', null);
      return 0;
    }
    const { positions, indices } = this.data;
    const corners = new Uint32Array(ids.length * 3);
    ids.forEach((f, i) => corners.set(indices.subarray(3 * f, 3 * f + 3), 3 * i));
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(cornerPositions(positions, corners), 3));
    g.computeBoundingSphere();
    const material = new THREE.MeshBasicMaterial({
      color: COLORS.selection, transparent: true, opacity: 0.5, side: THREE.DoubleSide, depthWrite: false,
      // In front of the (offset-back) surface it lies on, hidden behind the rest of the mesh.
      polygonOffset: true, polygonOffsetFactor: -1, polygonOffsetUnits: -2,
    });
    const mesh = new THREE.Mesh(g, material);
    mesh.renderOrder = 4;
    this.setOverlay('selection', mesh);
    return ids.length;
  }

  /** Position of a mesh vertex on the page (CSS px, client coordinates); null when behind the camera. */
  projectPoint(x: number, y: number, z: number): { x: number; y: number } | null {
    const v = new THREE.Vector3(x, y, z).applyMatrix4(this.group.matrixWorld).project(this.camera);
    if (v.z > 1 || v.z < -1) return null;
    const rect = this.canvas.getBoundingClientRect();
    return { x: rect.left + ((v.x + 1) / 2) * rect.width, y: rect.top + ((1 - v.y) / 2) * rect.height };
  }

  /** Picks the face under a page position and its nearest side and corner in screen space. */
  pick(clientX: number, clientY: number): Pick | null {
    if (!this.mesh || !this.data) return null;
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    // A plain raycast tests every triangle (no BVH): a few ms per 100k faces, only on clicks.
    const hit = this.raycaster.intersectObject(this.mesh, false)[0];
    if (!hit || hit.faceIndex === undefined || hit.faceIndex === null) return null;
    const face = hit.faceIndex;
    const { positions, indices } = this.data;
    const screen: Array<{ x: number; y: number }> = [];
    for (let k = 0; k < 3; k++) {
      const v = indices[3 * face + k]!;
      screen.push(this.projectPoint(positions[3 * v]!, positions[3 * v + 1]!, positions[3 * v + 2]!) ?? { x: Infinity, y: Infinity });
    }
    let side = 0;
    let sideDistance = Infinity;
    let vertex = indices[3 * face]!;
    let vertexDistance = Infinity;
    for (let k = 0; k < 3; k++) {
      const a = screen[k]!;
      const b = screen[(k + 1) % 3]!;
      const d = segmentDistance(clientX, clientY, a.x, a.y, b.x, b.y);
      if (d < sideDistance) {
        sideDistance = d;
        side = k;
      }
      const dv = Math.hypot(clientX - a.x, clientY - a.y);
      if (dv < vertexDistance) {
        vertexDistance = dv;
        vertex = indices[3 * face + k]!;
      }
    }
    return { face, side, sideDistance, vertex, vertexDistance, point: hit.point };
  }

  /** The orbit centre the camera looks at, mesh coordinates (a copy). */
  get target(): THREE.Vector3 {
    return this.controls.target.clone();
  }

  /** Turns the camera about the orbit centre by `left` and `up` radians (keyboard orbit). */
  orbit(left: number, up: number): void {
    const s = new THREE.Spherical().setFromVector3(this.camera.position.clone().sub(this.controls.target));
    s.theta -= left;
    s.phi = THREE.MathUtils.clamp(s.phi - up, 0.01, Math.PI - 0.01);
    this.camera.position.copy(this.controls.target).add(new THREE.Vector3().setFromSpherical(s));
    this.controls.update();
    this.loop.request();
  }

  /** Points the camera at the mesh's bounding sphere. */
  frame(): void {
    const sphere = this.mesh?.geometry.boundingSphere;
    if (!sphere) return;
    this.look(sphere.center, sphere.radius, new THREE.Vector3(0.55, 0.4, 1).normalize());
  }

  /**
   * Points the camera at the vertices `vertices` (ids of the shown mesh):
   * their bounding sphere (at least 15 % of the mesh's, for some context)
   * fills the view, seen from the side facing away from the mesh's centre.
   * False when none is valid.
   */
  frameOn(vertices: ArrayLike<number>): boolean {
    const sphere = this.mesh?.geometry.boundingSphere;
    if (!sphere || !this.data) return false;
    const p = this.data.positions;
    const points: THREE.Vector3[] = [];
    for (const v of Array.from(vertices)) if (v < p.length / 3) points.push(new THREE.Vector3(p[3 * v], p[3 * v + 1], p[3 * v + 2]));
    if (points.length === 0) return false;
    const around = new THREE.Sphere().setFromPoints(points);
    const outward = around.center.clone().sub(sphere.center);
    const dir = outward.length() > 1e-6 * sphere.radius ? outward.normalize() : this.camera.position.clone().sub(this.controls.target).normalize();
    this.look(around.center, Math.max(around.radius, sphere.radius * 0.15), dir);
    return true;
  }

  /** Camera at `center + dir * d` looking at `center`, `d` fitting a sphere of `radius` in the view; zoom limits from the whole mesh. */
  private look(center: THREE.Vector3, radius: number, dir: THREE.Vector3): void {
    const fov = THREE.MathUtils.degToRad(this.camera.fov);
    const fit = Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * this.camera.aspect));
    const fitting = (r: number): number => ((r > 0 ? r : 1) / Math.sin(fit / 2)) * 1.08;
    const r = radius > 0 ? radius : 1;
    const distance = fitting(r);
    const whole = this.mesh?.geometry.boundingSphere?.radius || r;
    this.camera.position.copy(center).addScaledVector(dir, distance);
    this.camera.near = distance / 100;
    this.camera.far = Math.max(distance, fitting(whole)) * 10;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(center);
    this.controls.minDistance = Math.min(r, whole) * 0.05;
    this.controls.maxDistance = fitting(whole) * 5;
    this.controls.update();
    this.loop.request();
  }

  private clear(): void {
    this.setUvSurface(null);
    for (const name of [...this.lines.keys()]) this.setLines(name, new Uint32Array(0), [], 0);
    this.setCones([], []);
    this.setAnchor(null);
    this.setProblemVertices([]);
    this.setHoverFace(null);
    for (const name of [...this.overlays.keys()]) this.setOverlay(name, null);
    this.markers.visible = true;
    for (const obj of [this.mesh, this.wire]) {
      if (!obj) continue;
      this.group.remove(obj);
      (obj.material as THREE.Material).dispose();
    }
    this.mesh?.geometry.dispose();
    this.wire?.geometry.dispose();
    this.mesh = null;
    this.wire = null;
    this.data = null;
  }

  private size = { w: 0, h: 0 };

  /** Fits the drawing buffer and camera to the container; nothing (no clear, no render) when its size is unchanged. */
  private resize(): void {
    const { clientWidth: w, clientHeight: h } = this.container;
    if (w === 0 || h === 0 || (w === this.size.w && h === this.size.h)) return;
    this.size = { w, h };
    this.renderer.setSize(w, h, false);
    this.renderer.domElement.style.width = '100%';
    this.renderer.domElement.style.height = '100%';
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    for (const m of this.lineMaterials) m.resolution.set(w, h);
    this.loop.request();
  }
}

function segmentDistance(px: number, py: number, ax: number, ay: number, bx: number, by: number): number {
  const dx = bx - ax;
  const dy = by - ay;
  const len2 = dx * dx + dy * dy;
  const t = len2 > 0 ? Math.max(0, Math.min(1, ((px - ax) * dx + (py - ay) * dy) / len2)) : 0;
  return Math.hypot(px - (ax + t * dx), py - (ay + t * dy));
}
