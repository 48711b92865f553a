// The 2D UV layout beside the 3D view: the parametrized triangles in an
// orthographic view (pan and zoom, no rotation), coloured by distortion when
// known, the [0, 1]² frame of the exports' texture space, the overlapping areas tinted (see uv-overlap.ts),
// the hovered face outlined and ringed in sync with the 3D view, the selected
// chart highlighted (a click picks a face, see chart-select.ts); an
// integer-grid map (quad mode) with its grid lines (see uv-grid.ts).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { LineMaterial } from 'three/examples/jsm/lines/LineMaterial.js';
import { LineSegments2 } from 'three/examples/jsm/lines/LineSegments2.js';
import { LineSegmentsGeometry } from 'three/examples/jsm/lines/LineSegmentsGeometry.js';
import { COLORS, checkerTexture } from './palette';
import { RenderLoop, createRenderer, latestPerFrame, onClick } from './render-loop';
import { gridLines, gridStride } from './uv-grid';
import { type UvOverlap, overlapText, overlapTint, uvOverlap } from './uv-overlap';

/** Which map of a solve a layout is: the seamless map, or the integer-grid map of the quads shown (grid units). */
export type UvMap = 'seamless' | 'grid';

/** The overlap figures of the map shown (see `UvOverlap`) and the milliseconds their rasterization took. */
export type UvOverlapFigures = Pick<UvOverlap, 'share' | 'maxDepth' | 'covered' | 'overlapped' | 'width' | 'height'> & { ms: number };

/**
 * What the view draws (for the test hooks): the map, the bounds of the drawn
 * triangles, the grid-line stride in cells (null: no grid lines), the
 * [0, 1]² frame of the exports (see `unitTile`; [min u, min v, max u, max v] in
 * the layout's units; null on a grid map), the
 * overlap figures, whether their tint is drawn, and the faces highlighted as
 * the selected chart.
 */
export interface UvDrawn {
  map: UvMap;
  bounds: [number, number, number, number];
  gridStride: number | null;
  frame: [number, number, number, number] | null;
  overlap: UvOverlapFigures;
  overlapTint: boolean;
  selectedFaces: number;
}

/**
 * The square the exports (OBJ, glTF) map to [0, 1]² for a seamless layout of
 * bounds `b` ([min u, min v, max u, max v]): from the lower-left corner, as
 * long as the longer side (crate `UvNormalization`).
 */
export function unitTile(b: readonly [number, number, number, number]): [number, number, number, number] {
  const side = Math.max(b[2] - b[0], b[3] - b[1]);
  return [b[0], b[1], b[0] + side, b[1] + side];
}


/** A UV layout to show (see `SolveView` in protocol.ts); the arrays are used as they are (not copied). */
export interface UvLayout {
  /** The map the UVs are of; a 'grid' map is drawn with its integer grid lines. */
  map: UvMap;
  /** The raw UVs, 2 per face corner 3f+k (for the hover highlight). */
  uv: Float32Array;
  /** xyz per corner (z = 0). */
  positions: Float32Array;
  /** UVs scaled for the checker texture, 2 per corner. */
  checkerUv: Float32Array;
  /** rgb per corner (distortion), or null. */
  colors: Float32Array | null;
  /** Chart outlines: 2 xyz points per segment. */
  outline: Float32Array;
  /** [min u, min v, max u, max v]. */
  bounds: [number, number, number, number];
  /** Bounding sphere of `positions`: [centre u, centre v, radius]. */
  sphere: [number, number, number];
}

export class UvView {
  private readonly renderer: THREE.WebGLRenderer;
  private readonly scene = new THREE.Scene();
  private readonly camera = new THREE.OrthographicCamera(-1, 1, 1, -1, -10, 10);
  private readonly controls: OrbitControls;
  /** The element the canvas fills (the pane's stage, or the container itself). */
  private readonly stage: HTMLElement;
  private mesh: THREE.Mesh | null = null;
  private edges: THREE.LineSegments | null = null;
  private hover: THREE.Mesh;
  /** The hovered face's outline (thick, in screen pixels) and a ring around its centroid: visible however small the face is drawn. */
  private readonly hoverOutline: LineSegments2;
  private readonly hoverRing: THREE.Points;
  private seams: THREE.LineSegments | null = null;
  private frameLines: THREE.LineSegments | null = null;
  /** The overlap tint: a textured quad over the coverage grid's bounds. */
  private tint: THREE.Mesh | null = null;
  private tintOn = true;
  /** Where the pane says how much of the map shown overlaps (null: nowhere). */
  private readonly overlapOut: HTMLOutputElement | null;
  private selection: THREE.Mesh | null = null;
  private checker: THREE.Texture | null = null;
  private uv: Float32Array | null = null;
  private readonly raycaster = new THREE.Raycaster();
  private bounds = new THREE.Box2();
  /** What is drawn (null: nothing). */
  private drawn: UvDrawn | null = null;
  /** The grid lines of a grid map at `drawn.gridStride`: minor, then major (empty ones left out). */
  private grid: THREE.LineSegments[] = [];
  /** Draws the layout on request (see `RenderLoop`). */
  readonly loop: RenderLoop;
  /** Called with the face under the pointer (null when none). */
  onHover: ((face: number | null) => void) | null = null;
  /** Called with the face clicked (null: a click on empty space); a drag pans and clicks nothing. */
  onSelect: ((face: number | null) => void) | null = null;
  /** Called whenever what is drawn changes (a layout shown or cleared, the grid stride after a zoom, the tint toggled). */
  onDrawn: ((drawn: UvDrawn | null) => void) | null = null;

  /** Draws into `container` (into its `.uv-stage` child when it has one; the `[data-uv=overlaps]` checkbox in it toggles the overlap tint). */
  constructor(container: HTMLElement) {
    this.stage = container.querySelector<HTMLElement>('.uv-stage') ?? container;
    this.renderer = createRenderer(this.stage, 'uv-canvas');
    this.loop = new RenderLoop(this.renderer, this.scene, this.camera);
    this.scene.background = new THREE.Color(0x20252d);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableRotate = false;
    this.controls.screenSpacePanning = true;
    this.controls.mouseButtons = { LEFT: THREE.MOUSE.PAN, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.PAN };
    // A pan or zoom by the user (a change between start and end) ends the fit.
    let interacting = false;
    this.controls.addEventListener('start', () => (interacting = true));
    this.controls.addEventListener('end', () => (interacting = false));
    this.controls.addEventListener('change', () => {
      if (interacting) this.fitted = false;
      this.updateGrid();
      this.loop.request();
    });
    const hg = new THREE.BufferGeometry();
    hg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(9), 3));
    this.hover = new THREE.Mesh(hg, new THREE.MeshBasicMaterial({ color: COLORS.hover, side: THREE.DoubleSide, depthTest: false }));
    this.hover.renderOrder = 8;
    const og = new LineSegmentsGeometry();
    og.setPositions(new Float32Array(18));
    this.hoverOutline = new LineSegments2(og, new LineMaterial({ color: COLORS.hover, linewidth: 2.5, worldUnits: false, depthTest: false }));
    this.hoverOutline.renderOrder = 9;
    const rg = new THREE.BufferGeometry();
    rg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3), 3));
    this.hoverRing = new THREE.Points(rg, new THREE.PointsMaterial({
      size: 26, sizeAttenuation: false, map: ringTexture(), color: COLORS.hover, transparent: true, depthTest: false,
    }));
    this.hoverRing.renderOrder = 10;
    for (const o of [this.hover, this.hoverOutline, this.hoverRing]) {
      o.visible = false;
      o.frustumCulled = false;
      this.scene.add(o);
    }

    const canvas = this.renderer.domElement;
    const hoverAt = latestPerFrame((e: PointerEvent) => this.onHover?.(this.pick(e.clientX, e.clientY)));
    canvas.addEventListener('pointermove', (e) => {
      if (!e.buttons) hoverAt(e);
    });
    canvas.addEventListener('pointerleave', () => this.onHover?.(null));
    onClick(canvas, (e) => {
      if (this.mesh) this.onSelect?.(this.pick(e.clientX, e.clientY));
    });
    const toggle = container.querySelector<HTMLInputElement>('[data-uv=overlaps]');
    toggle?.addEventListener('change', () => this.setOverlapTint(toggle.checked));
    this.overlapOut = container.querySelector<HTMLOutputElement>('[data-uv=overlap-text]');
    new ResizeObserver(() => this.resized()).observe(this.stage);
  }

  /** Colours the layout by distortion (when given to `show`) or plainly. */
  setColored(on: boolean): void {
    if (!this.mesh) return;
    const m = this.mesh.material as THREE.MeshBasicMaterial;
    const has = Boolean(this.mesh.geometry.getAttribute('color'));
    m.vertexColors = on && has;
    m.map = on && has ? null : (this.checker ??= checkerTexture());
    m.color.setHex(0xffffff);
    m.needsUpdate = true;
    this.loop.request();
  }

  /** The map shown (null: none). */
  get map(): UvMap | null {
    return this.drawn?.map ?? null;
  }

  /** The overlap figures of the map shown (null: none shown). */
  get overlap(): UvOverlapFigures | null {
    return this.drawn?.overlap ?? null;
  }

  /**
   * Shows a layout (its triangles, the chart outlines, triangle outlines when
   * small, grid lines for a grid map, the [0, 1]² frame for the seamless map,
   * its overlaps tinted) and frames it.
   */
  show(layout: UvLayout): void {
    this.clear();
    const { uv, positions: pos } = layout;
    this.uv = uv;
    const corners = uv.length / 2;
    const [minU, minV, maxU, maxV] = layout.bounds;
    if (corners > 0) this.bounds.set(new THREE.Vector2(minU, minV), new THREE.Vector2(maxU, maxV));
    else this.bounds.makeEmpty();
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    g.setAttribute('uv', new THREE.BufferAttribute(layout.checkerUv, 2));
    if (layout.colors) g.setAttribute('color', new THREE.BufferAttribute(layout.colors, 3));
    g.boundingSphere = new THREE.Sphere(new THREE.Vector3(layout.sphere[0], layout.sphere[1], 0), layout.sphere[2]);
    g.computeBoundingBox();
    const box = g.boundingBox!;
    const t0 = performance.now();
    const overlap = uvOverlap(uv);
    const { share, maxDepth, covered, overlapped, width, height } = overlap;
    // Drawn, not fit to: on a long layout most of the square is empty.
    const frame = layout.map === 'seamless' && corners > 0 ? unitTile(layout.bounds) : null;
    this.drawn = {
      map: layout.map, bounds: [box.min.x, box.min.y, box.max.x, box.max.y], gridStride: null, frame,
      overlap: { share, maxDepth, covered, overlapped, width, height, ms: performance.now() - t0 }, overlapTint: false,
      selectedFaces: 0,
    };
    this.mesh = new THREE.Mesh(g, new THREE.MeshBasicMaterial({ side: THREE.DoubleSide }));
    this.scene.add(this.mesh);
    this.setColored(false);
    if (layout.outline.length) {
      const sg = new THREE.BufferGeometry();
      sg.setAttribute('position', new THREE.BufferAttribute(layout.outline, 3));
      this.seams = new THREE.LineSegments(sg, new THREE.LineBasicMaterial({ color: COLORS.seam }));
      this.seams.renderOrder = 2;
      this.scene.add(this.seams);
    }
    // Triangle outlines only for layouts small enough to read.
    if (corners / 3 <= 4_000) {
      const idx = new Uint32Array(corners * 2);
      for (let f = 0; f < corners / 3; f++) {
        for (let k = 0; k < 3; k++) {
          idx[6 * f + 2 * k] = 3 * f + k;
          idx[6 * f + 2 * k + 1] = 3 * f + ((k + 1) % 3);
        }
      }
      const lg = new THREE.BufferGeometry();
      lg.setAttribute('position', g.getAttribute('position'));
      lg.setIndex(new THREE.BufferAttribute(idx, 1));
      this.edges = new THREE.LineSegments(lg, new THREE.LineBasicMaterial({ color: 0x111720, transparent: true, opacity: 0.35 }));
      this.scene.add(this.edges);
    }
    if (frame) {
      this.frameLines = frameLines(frame, 0.003);
      this.scene.add(this.frameLines);
    }
    if (overlapped > 0) {
      this.tint = tintMesh(overlap, 0.004);
      this.scene.add(this.tint);
    }
    this.applyTint();
    if (this.overlapOut) {
      this.overlapOut.textContent = overlapped ? `${(share * 100).toFixed(share < 0.1 ? 1 : 0)} %` : 'none';
      this.overlapOut.title = `UV overlap: ${overlapText(overlap)}`;
      this.overlapOut.classList.toggle('warn', overlapped > 0);
    }
    this.frame();
    this.onDrawn?.({ ...this.drawn });
  }

  /** Shows or hides the overlap tint. */
  setOverlapTint(on: boolean): void {
    this.tintOn = on;
    this.applyTint();
    if (this.drawn) this.onDrawn?.({ ...this.drawn });
    this.loop.request();
  }

  private applyTint(): void {
    if (this.tint) this.tint.visible = this.tintOn;
    if (this.drawn) this.drawn.overlapTint = this.tint !== null && this.tintOn;
  }

  /** Highlights the faces `faces` of the layout (the selected chart); null or none removes the highlight. Returns the faces highlighted. */
  setSelectedFaces(faces: Uint32Array | null): number {
    if (this.selection) drop(this.scene, this.selection);
    this.selection = null;
    const uv = this.uv;
    const ids = uv && faces ? Array.from(faces).filter((f) => 6 * f + 5 < uv.length) : [];
    if (uv && ids.length > 0) {
      const pos = new Float32Array(ids.length * 9);
      ids.forEach((f, i) => {
        for (let k = 0; k < 3; k++) {
          pos[9 * i + 3 * k] = uv[6 * f + 2 * k]!;
          pos[9 * i + 3 * k + 1] = uv[6 * f + 2 * k + 1]!;
          pos[9 * i + 3 * k + 2] = 0.006;
        }
      });
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
      g.computeBoundingSphere();
      this.selection = new THREE.Mesh(g, new THREE.MeshBasicMaterial({
        color: COLORS.selection, transparent: true, opacity: 0.45, side: THREE.DoubleSide, depthWrite: false,
      }));
      this.selection.renderOrder = 6;
      this.scene.add(this.selection);
    }
    if (this.drawn && this.drawn.selectedFaces !== ids.length) {
      this.drawn.selectedFaces = ids.length;
      this.onDrawn?.({ ...this.drawn });
    }
    this.loop.request();
    return ids.length;
  }

  /** Removes the layout shown. */
  clear(): void {
    this.setSelectedFaces(null);
    if (this.tint) ((this.tint.material as THREE.MeshBasicMaterial).map)?.dispose();
    for (const o of [this.mesh, this.edges, this.seams, this.frameLines, this.tint, ...this.grid]) if (o) drop(this.scene, o);
    this.mesh = null;
    this.edges = null;
    this.seams = null;
    this.frameLines = null;
    this.tint = null;
    this.grid = [];
    this.uv = null;
    this.setHoverFace(null);
    if (this.drawn) {
      this.drawn = null;
      this.onDrawn?.(null);
    }
    this.loop.request();
  }

  /** Fits the view to the layout's bounds; it stays fit through resizes until the user pans or zooms. */
  frame(): void {
    if (this.bounds.isEmpty()) return;
    const c = this.bounds.getCenter(new THREE.Vector2());
    this.controls.target.set(c.x, c.y, 0);
    this.camera.position.set(c.x, c.y, 5);
    this.camera.zoom = 1;
    this.fitted = true;
    this.resize();
    this.controls.update();
  }

  /** Whether the view is as `frame` left it (no pan or zoom since). */
  private fitted = false;

  /** Half the height (layout units) the camera shows at zoom 1: the bounds fit with a 10 % margin at aspect `aspect`. */
  private fitSpan(aspect: number): number {
    const s = this.bounds.getSize(new THREE.Vector2());
    return Math.max(s.y, s.x / aspect, 1e-9) * 0.55;
  }

  private span = 1;

  /**
   * For a grid map, draws the grid lines at the stride readable at the
   * current zoom (see `gridStride`) when it differs from the one drawn; tells
   * `onDrawn` of a new stride.
   */
  private updateGrid(): void {
    const d = this.drawn;
    if (!d || d.map !== 'grid' || this.size.h === 0) return;
    const pxPerCell = (this.size.h * this.camera.zoom) / (this.camera.top - this.camera.bottom);
    const stride = gridStride(pxPerCell);
    if (stride === d.gridStride) return;
    for (const o of this.grid) drop(this.scene, o);
    this.grid = [];
    d.gridStride = stride;
    if (stride !== null) {
      const lines = gridLines(d.bounds, stride, 0.002);
      // The quad edges lie on these lines: in their colour, faint every `stride` cells, stronger at each power of ten above.
      for (const [seg, opacity] of [[lines.minor, 0.3], [lines.major, 0.75]] as const) {
        if (seg.length === 0) continue;
        const lg = new THREE.BufferGeometry();
        lg.setAttribute('position', new THREE.BufferAttribute(seg, 3));
        const o = new THREE.LineSegments(lg, new THREE.LineBasicMaterial({ color: COLORS.quadEdge, transparent: true, opacity }));
        o.renderOrder = 1;
        this.grid.push(o);
        this.scene.add(o);
      }
    }
    this.onDrawn?.({ ...d });
    this.loop.request();
  }

  /** Page position (client CSS px) of the layout point (u, v). */
  projectPoint(u: number, v: number): { x: number; y: number } {
    this.camera.updateMatrixWorld();
    const rect = this.renderer.domElement.getBoundingClientRect();
    const p = new THREE.Vector3(u, v, 0).project(this.camera);
    return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height };
  }

  /**
   * Page position (client CSS px) of the centroid of face `face` in the
   * layout shown and the distance from it to the farthest corner (px); null
   * when there is no such face.
   */
  projectFace(face: number): { x: number; y: number; radius: number } | null {
    const uv = this.uv;
    if (!uv || 6 * face + 5 >= uv.length) return null;
    const corners = [0, 1, 2].map((k) => this.projectPoint(uv[6 * face + 2 * k]!, uv[6 * face + 2 * k + 1]!));
    const x = (corners[0]!.x + corners[1]!.x + corners[2]!.x) / 3;
    const y = (corners[0]!.y + corners[1]!.y + corners[2]!.y) / 3;
    return { x, y, radius: Math.max(...corners.map((c) => Math.hypot(c.x - x, c.y - y))) };
  }

  /** Highlights face `face` of the layout (null: none): filled, outlined thick and ringed, so that it shows however small it is drawn. */
  setHoverFace(face: number | null): void {
    const uv = this.uv;
    const shown = face !== null && uv !== null && 6 * face + 5 < uv.length;
    if (shown) {
      const a = this.hover.geometry.getAttribute('position') as THREE.BufferAttribute;
      const outline = new Float32Array(18);
      let cu = 0;
      let cv = 0;
      for (let k = 0; k < 3; k++) {
        const u = uv[6 * face + 2 * k]!;
        const v = uv[6 * face + 2 * k + 1]!;
        a.setXYZ(k, u, v, 0.01);
        const next = (k + 1) % 3;
        outline.set([u, v, 0.011, uv[6 * face + 2 * next]!, uv[6 * face + 2 * next + 1]!, 0.011], 6 * k);
        cu += u / 3;
        cv += v / 3;
      }
      a.needsUpdate = true;
      this.hoverOutline.geometry.setPositions(outline);
      const r = this.hoverRing.geometry.getAttribute('position') as THREE.BufferAttribute;
      r.setXYZ(0, cu, cv, 0.012);
      r.needsUpdate = true;
    }
    for (const o of [this.hover, this.hoverOutline, this.hoverRing]) o.visible = shown;
    this.loop.request();
  }

  private pick(clientX: number, clientY: number): number | null {
    if (!this.mesh) return null;
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    const hit = this.raycaster.intersectObject(this.mesh, false)[0];
    return hit?.faceIndex ?? null;
  }

  /** Drawing-buffer size last set, and whether a resize found the container hidden since. */
  private size = { w: 0, h: 0 };
  private stale = true;

  /** Applies a container size change (ResizeObserver): nothing when the size is the one applied and no resize was skipped. */
  private resized(): void {
    const { clientWidth: w, clientHeight: h } = this.stage;
    if (this.stale || w !== this.size.w || h !== this.size.h) this.resize();
  }

  private resize(): void {
    const { clientWidth: w, clientHeight: h } = this.stage;
    if (w === 0 || h === 0) {
      this.stale = true;
      return;
    }
    this.stale = false;
    // Setting the canvas size clears it: only when it changes.
    if (w !== this.size.w || h !== this.size.h) {
      this.size = { w, h };
      this.renderer.setSize(w, h, false);
      (this.hoverOutline.material as LineMaterial).resolution.set(w, h);
    }
    const aspect = w / h;
    if (this.fitted && !this.bounds.isEmpty()) this.span = this.fitSpan(aspect);
    const c = this.controls.target;
    this.camera.left = -this.span * aspect;
    this.camera.right = this.span * aspect;
    this.camera.top = this.span;
    this.camera.bottom = -this.span;
    this.camera.position.x = c.x;
    this.camera.position.y = c.y;
    this.camera.updateProjectionMatrix();
    this.updateGrid();
    this.loop.request();
  }
}

/** Takes `o` out of `scene` and frees the geometries and materials of it and its children (not the materials' textures). */
function drop(scene: THREE.Scene, o: THREE.Object3D): void {
  scene.remove(o);
  o.traverse((c) => {
    const m = c as THREE.Mesh;
    m.geometry?.dispose();
    (m.material as THREE.Material | undefined)?.dispose();
  });
}

/** The outline of the rectangle `rect` ([min u, min v, max u, max v]) at height `z`, in the frame colour. */
function frameLines(rect: readonly [number, number, number, number], z: number): THREE.LineSegments {
  const [u0, v0, u1, v1] = rect;
  const seg = Float32Array.from([u0, v0, z, u1, v0, z, u1, v0, z, u1, v1, z, u1, v1, z, u0, v1, z, u0, v1, z, u0, v0, z]);
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(seg, 3));
  const lines = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: COLORS.uvFrame, transparent: true, opacity: 0.8 }));
  lines.renderOrder = 1;
  // The square itself a shade lighter than the background, behind the layout.
  const fill = new THREE.Mesh(new THREE.PlaneGeometry(u1 - u0, v1 - v0), new THREE.MeshBasicMaterial({ color: 0x2a313c }));
  fill.position.set((u0 + u1) / 2, (v0 + v1) / 2, -0.01);
  lines.add(fill);
  return lines;
}

/** A quad over the coverage grid of `o` at height `z`, textured with its overlap tint (see `overlapTint`). */
function tintMesh(o: UvOverlap, z: number): THREE.Mesh {
  const c = new THREE.Color(COLORS.overlap);
  const rgb = [c.r, c.g, c.b].map((x) => Math.round(x * 255)) as [number, number, number];
  const texture = new THREE.DataTexture(overlapTint(o, rgb), o.width, o.height, THREE.RGBAFormat);
  texture.magFilter = THREE.NearestFilter;
  texture.minFilter = THREE.LinearFilter;
  texture.needsUpdate = true;
  const [u0, v0, u1, v1] = o.bounds;
  const g = new THREE.PlaneGeometry(u1 - u0, v1 - v0);
  g.translate((u0 + u1) / 2, (v0 + v1) / 2, z);
  const mesh = new THREE.Mesh(g, new THREE.MeshBasicMaterial({ map: texture, transparent: true, depthWrite: false }));
  mesh.renderOrder = 7; // over the selection: overlaps stay visible in a selected chart
  return mesh;
}

/** A ring (white outline on a dark halo) for the hover marker, as a texture. */
function ringTexture(): THREE.Texture {
  const size = 64;
  const c = document.createElement('canvas');
  c.width = c.height = size;
  const g = c.getContext('2d')!;
  g.lineWidth = 9;
  g.strokeStyle = 'rgba(10, 12, 16, 0.7)';
  g.beginPath();
  g.arc(size / 2, size / 2, size / 2 - 7, 0, 2 * Math.PI);
  g.stroke();
  g.lineWidth = 4.5;
  g.strokeStyle = '#ffffff';
  g.stroke();
  const t = new THREE.CanvasTexture(c);
  t.colorSpace = THREE.SRGBColorSpace;
  return t;
}
