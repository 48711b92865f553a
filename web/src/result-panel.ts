// A finished solve on screen: the figures table, the cones, seams and checker
// (or distortion) surface in the 3D view, the UV layout beside it with hover in
// sync (the seamless map, or the integer-grid map while quads are shown; its
// overlap as a figure, a chart clicked there selected in both views), the
// surface-mode switch with the distortion legend, and the downloads (glTF,
// OBJ, the JSON report); the quads of the map are quad-panel.ts.
import * as THREE from 'three';
import { ChartSelection } from './chart-select';
import { $, definitionList, fmt, fmtInt, fmtMs } from './dom';
import { download, downloadBytes, fileStem } from './downloads';
import type { OpenMesh } from './feature-editor';
import { COLORS, gridCheckerUv, heat } from './palette';
import type { SolveResult, SolveView } from './protocol';
import type { QuadPanel } from './quad-panel';
import { afterNextFrame, latestPerFrame } from './render-loop';
import { buildSolveView, cutSegments, layoutGeometry, uvBounds } from './solve-view';
import type { Hooks, ResultHook } from './test-hooks';
import { overlapText } from './uv-overlap';
import { type UvLayout, UvView } from './uvview';
import type { SurfaceMode, Viewer } from './viewer';

/** A solve's result as shown, with the mesh it was solved on and the settings it ran with. */
interface Shown {
  mesh: OpenMesh;
  result: SolveResult;
  settings: Record<string, unknown>;
}

export class ResultPanel {
  private shown: Shown | null = null;
  /** Bumped whenever the shown result is cleared: a view build that sees it change stops. */
  private epoch = 0;
  private readonly uvView: UvView;
  /** The chart clicked in the UV view, selected in both views. */
  private readonly charts: ChartSelection;
  /** The seamless map's layout of the result shown (null before it is on screen). */
  private seamless: UvLayout | null = null;
  private readonly el = {
    results: $('results'),
    resultStats: $('result-stats'),
    distortionLegend: $('distortion-legend'),
    distortionMax: $('distortion-max'),
    histogram: $<HTMLCanvasElement>('histogram'),
    glb: $<HTMLButtonElement>('download-glb'),
    obj: $<HTMLButtonElement>('download-obj'),
    json: $<HTMLButtonElement>('download-json'),
    uv: $('uv-view'),
    uvFrame: $<HTMLButtonElement>('uv-frame'),
  };

  /** `quads` is told of every map shown and cleared. */
  constructor(
    private readonly viewer: Viewer,
    private readonly hooks: Pick<Hooks, 'result' | 'hoverFace' | 'uvView' | 'chart'>,
    private readonly quads: QuadPanel,
  ) {
    this.uvView = new UvView(this.el.uv);
    this.uvView.onHover = (face) => this.hoverSync(face);
    this.uvView.onDrawn = (drawn) => (this.hooks.uvView = drawn);
    this.charts = new ChartSelection(viewer, this.uvView, hooks);
    this.wireHover();
    this.wireControls();
  }

  /** True while a result is shown (or being put on screen). */
  get hasResult(): boolean {
    return this.shown !== null;
  }

  /** Removes the shown result (figures, 3D overlays, UV layout); a view being built stops. */
  clear(): void {
    this.epoch++;
    this.shown = null;
    this.seamless = null;
    this.hooks.result = null;
    this.el.results.hidden = true;
    this.el.uv.hidden = true;
    this.charts.setMap(null);
    this.uvView.clear();
    this.viewer.setCones([], []);
    this.viewer.setLines('seams', new Uint32Array(0), [], COLORS.seam);
    this.viewer.setLines('unaligned', new Uint32Array(0), [], COLORS.unaligned);
    this.quads.setMap(null);
    this.viewer.setUvSurface(null);
    this.viewer.setHoverFace(null);
  }

  /**
   * Shows solve result `r` on mesh `m` (run with `settings`, for the report),
   * in place of the one shown: the figures at once; with UVs, then the 3D
   * surface with seams and cones in one frame and the UV layout in the next
   * (their shaders compiled first). Resolves true once all is shown, false when
   * `clear` was called on the way.
   */
  async show(m: OpenMesh, r: SolveResult, settings: Record<string, unknown>): Promise<boolean> {
    this.clear();
    this.shown = { mesh: m, result: r, settings };
    const epoch = this.epoch;
    const live = (): boolean => this.epoch === epoch;
    const figures = resultFigures(m, r);
    this.el.resultStats.replaceChildren(statsTable(m, r, figures));
    this.el.results.hidden = false;

    const hasUv = figures.uv;
    for (const radio of this.radios()) {
      radio.disabled = radio.value !== 'shaded' && !hasUv;
      radio.parentElement!.title = radio.disabled ? 'the result has no UVs for every face' : '';
      if (radio.value === 'shaded') radio.checked = !hasUv;
      if (radio.value === 'checker') radio.checked = hasUv;
    }
    this.el.glb.disabled = !r.glb;
    this.el.obj.disabled = !r.obj;
    this.el.json.disabled = false;
    this.el.distortionLegend.hidden = true;
    if (hasUv) {
      const view = r.view ?? buildView(m, r);
      const distortion = view.distortion;
      if (distortion) this.drawDistortionScale(distortion.max, distortion.histogram);
      const colors = distortion?.colors ?? null;
      // The 3D view: everything at once, so that it renders once (a full frame of a big mesh is costly).
      this.viewer.setCones(r.cones, r.boundary_corners);
      this.viewer.setUvSurface({ positions: view.cornerPositions, uv: view.checkerUv, colors });
      this.viewer.setSegments('seams', view.seamSegments, COLORS.seam, 2.5, 2);
      // Requested features the map left off an axis, drawn over everything.
      this.viewer.setLines('unaligned', m.edges, r.feature_alignment.unaligned.map((u) => u.edge), COLORS.unaligned, 5, 3);
      this.setSurface('checker');
      await this.viewer.loop.prepare();
      if (!live()) return false;
      await afterNextFrame();
      if (!live()) return false;
      // The UV layout, in the next frame.
      this.el.uv.hidden = false;
      this.seamless = {
        map: 'seamless', uv: r.uv, positions: view.layoutPositions, checkerUv: view.checkerUv, colors,
        outline: view.cutSegments, bounds: view.layoutBounds, sphere: view.layoutSphere,
      };
      this.uvView.show(this.seamless);
      this.uvView.setColored(this.surfaceMode() === 'distortion');
      this.charts.setMap({ faceEdges: m.data.faceEdges, edgeCount: m.edges.length / 2, seams: r.seam_edges ?? new Uint32Array(0) });
      const overlapRow = definitionList([['UV overlap', overlapText(this.uvView.overlap!)]]);
      this.el.resultStats.querySelector('dl')?.append(...overlapRow.childNodes);
      await this.uvView.loop.prepare();
      if (!live()) return false;
      await afterNextFrame();
      if (!live()) return false;
    } else {
      this.viewer.setCones(r.cones, r.boundary_corners);
      this.viewer.setSurfaceMode('shaded');
    }
    this.hooks.result = figures;
    if (hasUv) this.quads.setMap(m);
    return true;
  }

  /**
   * Draws the integer-grid map `uv` (grid units, 2 per face corner, as the
   * seamless UVs) in the UV view, framed, with its grid lines; null goes back
   * to the seamless map. Ignored until the seamless layout is on screen; a
   * `uv` of another length shows the seamless map.
   */
  showGridUv(uv: Float32Array | null): void {
    const seamless = this.seamless;
    if (!this.shown || !seamless) return;
    if (uv && uv.length === seamless.uv.length) {
      this.uvView.show(gridLayout(this.shown.mesh, this.shown.result, uv, seamless.colors));
    } else if (this.uvView.map !== 'seamless') {
      this.uvView.show(seamless);
    } else {
      return;
    }
    this.uvView.setColored(this.surfaceMode() === 'distortion');
    this.charts.reapply();
  }

  /** Page position (client CSS px) of the centroid of face `face` in the UV view and its farthest corner's distance; null when no layout is shown. */
  projectUvFace(face: number): { x: number; y: number; radius: number } | null {
    return this.uvView.projectFace(face);
  }

  /** Page position (client CSS px) of the layout point (u, v) in the UV view. */
  projectUvPoint(u: number, v: number): { x: number; y: number } {
    return this.uvView.projectPoint(u, v);
  }

  /** The report: settings, features, mesh figures and the solver's result (without bulky arrays); null without a result. */
  report(): Record<string, unknown> | null {
    if (!this.shown) return null;
    const { mesh: m, result: r, settings } = this.shown;
    const { uv: _uv, glb: _glb, obj: _obj, view: _view, seam_edges: seams, metrics, ...rest } = r;
    const metricsOut = { ...metrics, per_face_distortion: undefined };
    return {
      tool: 'conemap',
      file: m.label,
      mesh: m.data.report,
      settings,
      features: {
        edges: Array.from(m.features?.ids() ?? []),
        // End positions too: the same form as `conemap solve --features FILE`.
        positions: Array.from(m.features?.ids() ?? [], (e) => [m.edges[2 * e]!, m.edges[2 * e + 1]!].map((v) => Array.from(m.data.positions.subarray(3 * v, 3 * v + 3)))),
        boundary_edges: m.features?.boundaryCount ?? 0,
      },
      result: { ...rest, metrics: metricsOut, seam_edges: seams.length },
    };
  }

  /** Highlights the same face in the 3D view and the UV view. */
  private hoverSync(face: number | null): void {
    this.hooks.hoverFace = face;
    this.viewer.setHoverFace(face);
    this.uvView.setHoverFace(face);
  }

  /** Hover sync from the 3D view, only while a UV layout is shown. */
  private wireHover(): void {
    const canvas = this.viewer.canvas;
    const hoverAt = latestPerFrame((e: PointerEvent) => this.hoverSync(this.viewer.pick(e.clientX, e.clientY)?.face ?? null));
    canvas.addEventListener('pointermove', (e) => {
      if (!e.buttons && !this.el.uv.hidden) hoverAt(e);
    });
    canvas.addEventListener('pointerleave', () => {
      if (!this.el.uv.hidden) this.hoverSync(null);
    });
  }

  private wireControls(): void {
    for (const radio of this.radios()) {
      radio.addEventListener('change', () => {
        if (radio.checked) this.setSurface(radio.value as SurfaceMode);
      });
    }
    this.el.uvFrame.addEventListener('click', () => this.uvView.frame());
    this.el.json.addEventListener('click', () => {
      const report = this.report();
      if (report) download(new Blob([`${JSON.stringify(report, null, 2)}\n`], { type: 'application/json' }), `${this.baseName()}-report.json`);
    });
    this.el.glb.addEventListener('click', () => {
      const glb = this.shown?.result.glb;
      if (glb) downloadBytes(glb, 'model/gltf-binary', `${this.baseName()}-uv.glb`);
    });
    this.el.obj.addEventListener('click', () => {
      const obj = this.shown?.result.obj;
      if (obj) downloadBytes(obj, 'text/plain', `${this.baseName()}-uv.obj`);
    });
  }

  private radios(): NodeListOf<HTMLInputElement> {
    return document.querySelectorAll<HTMLInputElement>('input[name=surface]');
  }

  /** The surface mode of the checked radio button ('shaded' when none is). */
  private surfaceMode(): SurfaceMode {
    return (document.querySelector<HTMLInputElement>('input[name=surface]:checked')?.value as SurfaceMode | undefined) ?? 'shaded';
  }

  private setSurface(mode: SurfaceMode): void {
    for (const radio of this.radios()) radio.checked = radio.value === mode;
    this.viewer.setSurfaceMode(mode);
    this.uvView.setColored(mode === 'distortion');
    this.el.distortionLegend.hidden = mode !== 'distortion' || !this.shown;
  }

  /** The distortion legend: its scale `max` and the histogram of `counts` (equal bins of value / max over 0..1). */
  private drawDistortionScale(max: number, counts: Uint32Array): void {
    this.el.distortionMax.textContent = fmt(max);
    const canvas = this.el.histogram;
    const g = canvas.getContext('2d')!;
    const bins = counts.length;
    const top = Math.max(...counts, 1);
    g.clearRect(0, 0, canvas.width, canvas.height);
    const w = canvas.width / bins;
    const col = new THREE.Color();
    for (let i = 0; i < bins; i++) {
      const h = (counts[i]! / top) * (canvas.height - 4);
      heat((i + 0.5) / bins, col);
      g.fillStyle = `#${col.getHexString()}`;
      g.fillRect(i * w + 0.5, canvas.height - h, w - 1, h);
    }
  }

  /** The file name stem of the downloads (see `fileStem`). */
  private baseName(): string {
    return fileStem(this.shown?.mesh.label);
  }
}

/** Takes a result `r` on mesh `m` and returns its figures for the test hooks (and the cone count as shown). */
function resultFigures(m: OpenMesh, r: SolveResult): ResultHook {
  const plus = r.cones.filter((c) => c.k > 0).length;
  const minus = r.cones.filter((c) => c.k < 0).length;
  return {
    cones: r.cones.length,
    plus,
    minus,
    sumConeK: r.cones.reduce((s, c) => s + c.k, 0),
    sumCornerK: r.boundary_corners.reduce((s, c) => s + c.k, 0),
    boundaryCorners: r.boundary_corners.length,
    eulerCharacteristic: m.data.report?.euler_characteristic ?? NaN,
    rounds: r.rounds,
    featureEdges: r.feature_edges,
    shownCones: `${fmtInt(r.cones.length)} (+${plus} / −${minus})`,
    uv: r.uv.length === (m.data.indices.length / 3) * 6,
    seams: r.seam_edges.length,
    energy: r.energy,
    helperComponents: r.helperComponents ?? 0,
    uvBounds: r.uv.length > 0 ? uvBounds(r.uv) : null,
  };
}

/** Takes a result `r` on mesh `m` and its figures `f`; returns the figures table of the results panel. */
function statsTable(m: OpenMesh, r: SolveResult, f: ResultHook): HTMLDListElement {
  const report = m.data.report;
  const genus = report?.genus?.length ? report.genus.join(', ') : '—';
  const rows: Array<[string, string]> = [
    ['Vertices', fmtInt(m.data.positions.length / 3)],
    ['Faces', fmtInt(m.data.indices.length / 3)],
    ['Genus', genus],
    ['Boundary loops', report ? fmtInt(report.boundary_loops) : '—'],
    ['Features', fmtInt(r.feature_edges)],
    ['Cones', f.shownCones],
    ['Boundary corners', fmtInt(r.boundary_corners.length)],
    r.free_boundary
      ? ['Σk (cones)', `${f.sumConeK} (free boundary: its curvature takes the rest of 4χ)`]
      : ['Σk (cones + corners)', `${f.sumConeK + f.sumCornerK} = 4χ = ${4 * f.eulerCharacteristic}`],
    ['Energy', fmt(r.energy, 4)],
    ['φ rms', fmt(r.phi_rms, 4)],
    ['Rounding rounds', fmtInt(r.rounds)],
  ];
  const metrics = r.metrics;
  rows.push(
    ['Distortion', fmt(metrics.distortion)],
    ['Faces < 0.2 / < 0.3', `${fmt(metrics.fraction_below_0_2 * 100, 1)} % / ${fmt(metrics.fraction_below_0_3 * 100, 1)} %`],
    ['Flipped faces', fmtInt(metrics.flipped)],
    ['Seam length', fmt(metrics.seam_length)],
    ['Seam residual (angle / length)', `${fmt(metrics.seam_angle_residual)} / ${fmt(metrics.seam_length_residual)}`],
    ['Alignment residual', fmt(metrics.alignment_residual)],
  );
  // Components may be placed in parallel (a helper worker): their stage
  // times add up over components, the cone total is wall-clock.
  const summed = new Set(['topology', 'rounding', 'cone_moves']);
  for (const [k, v] of Object.entries(r.timings)) {
    const label = k === 'total' ? 'cones total' : `${k.replace(/_/g, ' ')}${summed.has(k) ? ' (Σ components)' : ''}`;
    rows.push([`Time: ${label}`, fmtMs(v * 1000)]);
  }
  for (const [k, v] of Object.entries(r.param_timings)) {
    rows.push([`Time: ${k.replace(/_/g, ' ')} (UV)`, fmtMs(v * 1000)]);
  }
  if (r.inserted_vertices > 0) rows.push(['Inserted vertices (refinement)', fmtInt(r.inserted_vertices)]);
  const alignment = r.feature_alignment;
  if (alignment.requested > 0) {
    const off = alignment.unaligned.slice(0, 5).map((u) => `(v${u.vertices[0]}, v${u.vertices[1]}) ${u.degrees.toFixed(1)}°`).join(', ');
    rows.push(['Features on isolines', `${fmtInt(alignment.aligned)} / ${fmtInt(alignment.requested)}${off ? ` — off: ${off}` : ''}`]);
  }
  rows.push(['Time in worker', fmtMs(r.elapsed)]);
  const list = definitionList(rows);
  const coneDd = list.querySelector<HTMLElement>('dd[data-stat=cones]');
  if (coneDd) coneDd.dataset['testid'] = 'cone-count';
  return list;
}

/** The UV layout of the integer-grid map `uv` of result `r` on mesh `m` (its chart outlines along the same seams), coloured by `colors` (the seamless map's distortion, as in the 3D view). */
function gridLayout(m: OpenMesh, r: SolveResult, uv: Float32Array, colors: Float32Array | null): UvLayout {
  const g = layoutGeometry(uv);
  return {
    map: 'grid', uv, positions: g.layoutPositions, checkerUv: gridCheckerUv(uv), colors,
    outline: cutSegments(uv, m.data.faceEdges, m.edges.length / 2, r.seam_edges ?? new Uint32Array(0), m.data.boundary),
    bounds: g.layoutBounds, sphere: g.layoutSphere,
  };
}

/** The display arrays of result `r` on mesh `m` built on this thread (when the worker sent none). */
function buildView(m: OpenMesh, r: SolveResult): SolveView {
  return buildSolveView({
    positions: m.data.positions, indices: m.data.indices, edges: m.edges, boundary: m.data.boundary,
    faceEdges: m.data.faceEdges, uv: r.uv, seamEdges: r.seam_edges ?? null,
    perFaceDistortion: r.metrics?.per_face_distortion ?? null,
  });
}
