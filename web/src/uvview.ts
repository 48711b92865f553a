// The 2D UV layout beside the 3D view: the parametrized triangles in an
// orthographic view (pan and zoom, no rotation), coloured by distortion when
// known, with the hovered face highlighted in sync with the 3D view; an
// integer-grid map (quad mode) with its grid lines (see uv-grid.ts).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { COLORS, checkerTexture } from './palette';
import { RenderLoop, createRenderer, latestPerFrame } from './render-loop';
import { gridLines, gridStride } from './uv-grid';

/** Which map of a solve a layout is: the seamless map, or the integer-grid map of the quads shown (grid units). */
export type UvMap = 'seamless' | 'grid';

/** What the view draws (for the test hooks): the map, the bounds of the drawn triangles, the grid-line stride in cells (null: no grid lines). */
export interface UvDrawn {
  map: UvMap;
  bounds: [number, number, number, number];
  gridStride: number | null;
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
  private mesh: THREE.Mesh | null = null;
  private edges: THREE.LineSegments | null = null;
  private hover: THREE.Mesh;
  private seams: THREE.LineSegments | null = null;
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
  /** Called whenever what is drawn changes (a layout shown or cleared, the grid stride after a zoom). */
  onDrawn: ((drawn: UvDrawn | null) => void) | null = null;

  constructor(private readonly container: HTMLElement) {
    this.renderer = createRenderer(container, 'uv-canvas');
    this.loop = new RenderLoop(this.renderer, this.scene, this.camera);
    this.scene.background = new THREE.Color(0x20252d);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableRotate = false;
    this.controls.screenSpacePanning = true;
    this.controls.mouseButtons = { LEFT: THREE.MOUSE.PAN, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.PAN };
    this.controls.addEventListener('change', () => {
      this.updateGrid();
      this.loop.request();
    });
    const hg = new THREE.BufferGeometry();
    hg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(9), 3));
    this.hover = new THREE.Mesh(hg, new THREE.MeshBasicMaterial({ color: COLORS.hover, side: THREE.DoubleSide, depthTest: false }));
    this.hover.visible = false;
    this.hover.renderOrder = 3;
    this.scene.add(this.hover);

    const hoverAt = latestPerFrame((e: PointerEvent) => this.onHover?.(this.pick(e.clientX, e.clientY)));
    this.renderer.domElement.addEventListener('pointermove', (e) => {
      if (!e.buttons) hoverAt(e);
    });
    this.renderer.domElement.addEventListener('pointerleave', () => this.onHover?.(null));
    new ResizeObserver(() => this.resized()).observe(container);
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

  /** Shows a layout (its triangles, the chart outlines, triangle outlines when small, grid lines for a grid map) and frames it. */
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
    const drawn: UvDrawn = { map: layout.map, bounds: [box.min.x, box.min.y, box.max.x, box.max.y], gridStride: null };
    this.drawn = drawn;
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
    this.frame();
    this.onDrawn?.({ ...drawn });
  }

  /** Removes the layout shown. */
  clear(): void {
    for (const o of [this.mesh, this.edges, this.seams, ...this.grid]) {
      if (!o) continue;
      this.scene.remove(o);
      o.geometry.dispose();
      (o.material as THREE.Material).dispose();
    }
    this.mesh = null;
    this.edges = null;
    this.seams = null;
    this.grid = [];
    this.uv = null;
    this.hover.visible = false;
    if (this.drawn) {
      this.drawn = null;
      this.onDrawn?.(null);
    }
    this.loop.request();
  }

  /** Fits the view to the layout's bounds. */
  frame(): void {
    if (this.bounds.isEmpty()) return;
    const c = this.bounds.getCenter(new THREE.Vector2());
    const s = this.bounds.getSize(new THREE.Vector2());
    this.controls.target.set(c.x, c.y, 0);
    this.camera.position.set(c.x, c.y, 5);
    this.camera.zoom = 1;
    this.span = Math.max(s.x, s.y, 1e-9) * 0.55;
    this.resize();
    this.controls.update();
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
    for (const o of this.grid) {
      this.scene.remove(o);
      o.geometry.dispose();
      (o.material as THREE.Material).dispose();
    }
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

  /**
   * Page position (client CSS px) of the centroid of face `face` in the
   * layout shown and the distance from it to the farthest corner (px); null
   * when there is no such face.
   */
  projectFace(face: number): { x: number; y: number; radius: number } | null {
    if (!this.uv || 6 * face + 5 >= this.uv.length) return null;
    this.camera.updateMatrixWorld();
    const rect = this.renderer.domElement.getBoundingClientRect();
    const corners = [0, 1, 2].map((k) => {
      const p = new THREE.Vector3(this.uv![6 * face + 2 * k], this.uv![6 * face + 2 * k + 1], 0).project(this.camera);
      return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height };
    });
    const x = (corners[0]!.x + corners[1]!.x + corners[2]!.x) / 3;
    const y = (corners[0]!.y + corners[1]!.y + corners[2]!.y) / 3;
    return { x, y, radius: Math.max(...corners.map((c) => Math.hypot(c.x - x, c.y - y))) };
  }

  /** Highlights face `face` of the layout (null: none). */
  setHoverFace(face: number | null): void {
    if (face === null || !this.uv || 6 * face + 5 >= this.uv.length) {
      this.hover.visible = false;
    } else {
      const a = this.hover.geometry.getAttribute('position') as THREE.BufferAttribute;
      for (let k = 0; k < 3; k++) a.setXYZ(k, this.uv[6 * face + 2 * k]!, this.uv[6 * face + 2 * k + 1]!, 0.01);
      a.needsUpdate = true;
      this.hover.geometry.computeBoundingSphere();
      this.hover.visible = true;
    }
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
    const { clientWidth: w, clientHeight: h } = this.container;
    if (this.stale || w !== this.size.w || h !== this.size.h) this.resize();
  }

  private resize(): void {
    const { clientWidth: w, clientHeight: h } = this.container;
    if (w === 0 || h === 0) {
      this.stale = true;
      return;
    }
    this.stale = false;
    // Setting the canvas size clears it: only when it changes.
    if (w !== this.size.w || h !== this.size.h) {
      this.size = { w, h };
      this.renderer.setSize(w, h, false);
    }
    const aspect = w / h;
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
