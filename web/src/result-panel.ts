// A finished solve on screen: the actions first (surface switch, downloads),
// the figures that matter (cones, distortion, flipped faces, time) and the
// rest folded in a details section; the cones, seams and checker (or
// distortion) surface in the 3D view, the UV layout beside it with hover in
// sync (the seamless map, or the integer-grid map while quads are shown; its
// overlap as a figure, a chart clicked there selected in both views), the
// checker density, the distortion legend (distortion-legend.ts) and the
// downloads (glTF, OBJ, the JSON report) of the run shown; the quads of the
// map are quad-panel.ts, the runs to switch between run-history.ts.
import { ChartSelection } from './chart-select';
import { $, definitionList, fmt, fmtAlpha, fmtDuration, fmtInt, fmtMs, termLabel } from './dom';
import { DistortionLegend } from './distortion-legend';
import { download, downloadBytes, fileStem } from './downloads';
import type { OpenMesh } from './feature-editor';
import { CHECKER_BASE_SQUARES, COLORS, gridCheckerUv, setCheckerRepeat } from './palette';
import type { SolveResult, SolveView } from './protocol';
import type { QuadPanel } from './quad-panel';
import { afterNextFrame, latestPerFrame } from './render-loop';
import type { Run } from './run-history';
import { buildSolveView, cutSegments, distortionView, layoutGeometry, uvBounds } from './solve-view';
import type { DistortionHook, Hooks, ResultHook } from './test-hooks';
import { overlapText } from './uv-overlap';
import { type UvLayout, UvView } from './uvview';
import type { SurfaceMode, Viewer } from './viewer';

/** A run as shown: the run and its display arrays (null without UVs), coloured at the legend's scale. */
interface Shown {
  run: Run;
  view: SolveView | null;
}

export class ResultPanel {
  private shown: Shown | null = null;
  /** Bumped whenever the shown result is cleared: a view build that sees it change stops. */
  private epoch = 0;
  private readonly uvView: UvView;
  /** The chart clicked in the UV view, selected in both views. */
  private readonly charts: ChartSelection;
  private readonly legend = new DistortionLegend();
  /** The seamless map's layout of the result shown (null before it is on screen). */
  private seamless: UvLayout | null = null;
  /** The integer-grid UVs drawn in place of the seamless map's (quads shown), or null. */
  private gridUv: Float32Array | null = null;
  private readonly el = {
    results: $('results'),
    run: $('result-run'),
    summary: $('result-summary'),
    resultStats: $('result-stats'),
    distortionLegend: $('distortion-legend'),
    checkerOptions: $('checker-options'),
    checkerDensity: $<HTMLSelectElement>('checker-density'),
    glb: $<HTMLButtonElement>('download-glb'),
    obj: $<HTMLButtonElement>('download-obj'),
    json: $<HTMLButtonElement>('download-json'),
    uv: $('uv-view'),
    uvFrame: $<HTMLButtonElement>('uv-frame'),
  };

  /** `quads` is told of every map shown and cleared. */
  constructor(
    private readonly viewer: Viewer,
    private readonly hooks: Pick<Hooks, 'result' | 'hoverFace' | 'uvView' | 'chart' | 'distortion' | 'checkerSquares'>,
    private readonly quads: QuadPanel,
  ) {
    this.uvView = new UvView(this.el.uv);
    this.uvView.onHover = (face) => this.hoverSync(face);
    this.uvView.onDrawn = (drawn) => (this.hooks.uvView = drawn);
    this.charts = new ChartSelection(viewer, this.uvView, hooks);
    this.legend.onChange = () => this.recolor();
    this.wireHover();
    this.wireControls();
    this.applyCheckerDensity();
  }

  /** True while a result is shown (or being put on screen). */
  get hasResult(): boolean {
    return this.shown !== null;
  }

  /** The run shown (or being put on screen), null when none is. */
  get run(): Run | null {
    return this.shown?.run ?? null;
  }

  /** Removes the shown result (figures, 3D overlays, UV layout); a view being built stops. */
  clear(): void {
    this.epoch++;
    this.shown = null;
    this.seamless = null;
    this.hooks.result = null;
    this.hooks.distortion = null;
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
   * Shows `run` in place of the one shown: the figures at once; with UVs,
   * then the 3D surface with seams and cones in one frame and the UV layout
   * in the next (their shaders compiled first), coloured at the legend's
   * scale. With `withQuads`, the quad panel may ask for the quads of its map
   * (the worker holds the newest solve's only). Resolves true once all is
   * shown, false when `clear` was called on the way.
   */
  async show(run: Run, withQuads = true): Promise<boolean> {
    this.clear();
    const { mesh: m, result: r } = run;
    const shown: Shown = { run, view: null };
    this.shown = shown;
    const epoch = this.epoch;
    const live = (): boolean => this.epoch === epoch;
    const figures = resultFigures(m, r);
    this.el.run.textContent = `Run ${run.n} · α ${fmtAlpha(run.settings.alpha_smooth)}`;
    this.el.summary.replaceChildren(...summaryFigures(run, figures));
    this.el.resultStats.replaceChildren(statsTable(run, figures));
    this.el.results.hidden = false;

    const hasUv = figures.uv;
    // A result with UVs opens on the checker, or on the distortion when that was shown (comparing runs).
    const mode: SurfaceMode = !hasUv ? 'shaded' : this.surfaceMode() === 'distortion' ? 'distortion' : 'checker';
    for (const radio of this.radios()) {
      radio.disabled = radio.value !== 'shaded' && !hasUv;
      radio.parentElement!.title = radio.disabled ? 'the result has no UVs for every face' : '';
    }
    this.el.glb.disabled = !r.glb;
    this.el.obj.disabled = !r.obj;
    this.el.json.disabled = false;
    this.el.distortionLegend.hidden = true;
    this.el.checkerOptions.hidden = true;
    if (hasUv) {
      const view = this.colored(r.view ?? buildView(m, r), r);
      shown.view = view;
      const colors = view.distortion?.colors ?? null;
      // The 3D view: everything at once, so that it renders once (a full frame of a big mesh is costly).
      this.viewer.setCones(r.cones, r.boundary_corners);
      this.viewer.setUvSurface({ positions: view.cornerPositions, uv: view.checkerUv, colors });
      this.viewer.setSegments('seams', view.seamSegments, COLORS.seam, 2.5, 2);
      // Requested features the map left off an axis, drawn over everything.
      this.viewer.setLines('unaligned', m.edges, r.feature_alignment.unaligned.map((u) => u.edge), COLORS.unaligned, 5, 3);
      this.setSurface(mode);
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
      this.setSurface(mode);
    }
    this.hooks.result = figures;
    if (hasUv && withQuads) this.quads.setMap(m);
    return true;
  }

  /**
   * Draws the integer-grid map `uv` (grid units, 2 per face corner, as the
   * seamless UVs) in the UV view, framed, with its grid lines, one checker
   * square per cell; null goes back to the seamless map. Ignored until the
   * seamless layout is on screen; a `uv` of another length shows the
   * seamless map.
   */
  showGridUv(uv: Float32Array | null): void {
    const seamless = this.seamless;
    this.gridUv = seamless && uv && uv.length === seamless.uv.length ? uv : null;
    this.applyCheckerDensity();
    if (!this.shown || !seamless) return;
    if (this.gridUv) {
      this.uvView.show(gridLayout(this.shown.run, this.gridUv, seamless.colors));
    } else if (this.uvView.map !== 'seamless') {
      this.uvView.show(seamless);
    } else {
      return;
    }
    this.uvView.setColored(this.surfaceMode() === 'distortion');
    this.charts.reapply();
  }

  /** Scrolls the panel as little as needed to bring the surface switch and the downloads into view (after a fresh solve). */
  revealActions(): void {
    this.el.glb.parentElement?.scrollIntoView({ block: 'nearest' });
  }

  /** Page position (client CSS px) of the centroid of face `face` in the UV view and its farthest corner's distance; null when no layout is shown. */
  projectUvFace(face: number): { x: number; y: number; radius: number } | null {
    return this.uvView.projectFace(face);
  }

  /** Page position (client CSS px) of the layout point (u, v) in the UV view. */
  projectUvPoint(u: number, v: number): { x: number; y: number } {
    return this.uvView.projectPoint(u, v);
  }

  /** The report: settings, features, mesh figures, the solver's result and the quads shown (without bulky arrays); null without a result. */
  report(): Record<string, unknown> | null {
    if (!this.shown) return null;
    const { mesh: m, result: r, settings } = this.shown.run;
    const { uv: _uv, glb: _glb, obj: _obj, view: _view, seam_edges: seams, metrics, ...rest } = r;
    const metricsOut = { ...metrics, per_face_distortion: undefined };
    const quads = this.quads.reportSection();
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
        // Those marked by the Creases button: the quads drop them where they fold the map.
        creases: Array.from(m.features?.creaseIds() ?? []),
      },
      result: { ...rest, metrics: metricsOut, seam_edges: seams.length },
      // The quads shown of this result's map, if any.
      ...(quads ? { quads } : {}),
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
    this.el.checkerDensity.addEventListener('change', () => this.applyCheckerDensity());
    this.el.uvFrame.addEventListener('click', () => this.uvView.frame());
    this.el.json.addEventListener('click', () => {
      const report = this.report();
      if (report) download(new Blob([`${JSON.stringify(report, null, 2)}\n`], { type: 'application/json' }), `${this.baseName()}-report.json`);
    });
    this.el.glb.addEventListener('click', () => {
      const glb = this.shown?.run.result.glb;
      if (glb) downloadBytes(glb, 'model/gltf-binary', `${this.baseName()}-uv.glb`);
    });
    this.el.obj.addEventListener('click', () => {
      const obj = this.shown?.run.result.obj;
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

  /** Shows surface `mode` in both views, with its options (the checker density, the distortion legend). */
  private setSurface(mode: SurfaceMode): void {
    for (const radio of this.radios()) radio.checked = radio.value === mode;
    this.viewer.setSurfaceMode(mode);
    this.uvView.setColored(mode === 'distortion');
    const distortion = this.shown?.view?.distortion ?? null;
    this.el.distortionLegend.hidden = mode !== 'distortion' || !distortion;
    this.el.checkerOptions.hidden = mode !== 'checker' || !this.shown?.view;
  }

  /**
   * `view` with its distortion coloured at the legend's scale (the worker
   * colours at the auto scale: a fixed one is recoloured here), the legend
   * drawn and the test hook set.
   */
  private colored(view: SolveView, r: SolveResult): SolveView {
    const perFace = r.metrics.per_face_distortion;
    const fixed = this.legend.fixedScale;
    const distortion = perFace && (fixed !== undefined || !view.distortion) ? distortionView(perFace, fixed) : view.distortion;
    if (distortion) {
      this.legend.draw(distortion.max, distortion.histogram);
      this.hooks.distortion = distortionHook(distortion, fixed !== undefined);
    }
    return distortion === view.distortion ? view : { ...view, distortion };
  }

  /** After a change of the scale: the shown result's distortion coloured again in both views (the grid map kept while quads are shown, the selected chart kept). */
  private recolor(): void {
    const s = this.shown;
    const seamless = this.seamless;
    if (!s?.view || !seamless) return;
    const view = this.colored({ ...s.view, distortion: null }, s.run.result);
    s.view = view;
    const colors = view.distortion?.colors ?? null;
    this.viewer.setUvSurface({ positions: view.cornerPositions, uv: view.checkerUv, colors });
    if (this.gridUv) this.viewer.setGridUv(this.gridUv);
    this.seamless = { ...seamless, colors };
    this.uvView.show(this.gridUv ? gridLayout(s.run, this.gridUv, colors) : this.seamless);
    this.uvView.setColored(this.surfaceMode() === 'distortion');
    this.charts.reapply();
  }

  /**
   * The checker at the density selected (squares across the seamless
   * layout's larger side), or one square per grid cell while the grid map is
   * drawn (the control is off then); both views draw it at their next frame.
   */
  private applyCheckerDensity(): void {
    const select = this.el.checkerDensity;
    const squares = Number(select.value) || CHECKER_BASE_SQUARES;
    select.disabled = this.gridUv !== null;
    select.title = this.gridUv ? 'While quads are shown the checker has one square per grid cell' : '';
    setCheckerRepeat(this.gridUv ? 1 : squares / CHECKER_BASE_SQUARES);
    this.hooks.checkerSquares = this.gridUv ? null : squares;
    this.viewer.loop.request();
    this.uvView.loop.request();
  }

  /** The file name stem of the downloads (see `fileStem`). */
  private baseName(): string {
    return fileStem(this.shown?.run.mesh.label);
  }
}

/** The test hook of distortion colours `d` (`fixed`: at a fixed scale): the scale, the histogram and the mean colour over faces. */
function distortionHook(d: NonNullable<SolveView['distortion']>, fixed: boolean): DistortionHook {
  const mean = [0, 0, 0];
  const faces = d.colors.length / 9;
  for (let f = 0; f < faces; f++) for (let k = 0; k < 3; k++) mean[k]! += d.colors[9 * f + k]!;
  return { scale: d.max, fixed, histogram: Array.from(d.histogram), meanColor: mean.map((x) => x / Math.max(faces, 1)) as [number, number, number] };
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

/** The headline figures of `run` (figures `f`): cones, mean distortion, flipped faces, time from Run to result; a dt / dd pair each (jargon explained as in the tables), the dd's `data-stat` its key. */
function summaryFigures(run: Run, f: ResultHook): HTMLDivElement[] {
  const m = run.result.metrics;
  const items: Array<[string, string, string, string]> = [
    ['cones', 'Cones', fmtInt(f.cones), `(+${f.plus} / −${f.minus})`],
    ['distortion', 'Distortion', fmt(m.distortion), 'mean'],
    ['flipped', 'Flipped faces', fmtInt(m.flipped), ''],
    ['time', 'Time', fmtDuration(run.settings.wall_ms), ''],
  ];
  return items.map(([key, label, value, note]) => {
    const item = document.createElement('div');
    const dt = termLabel(label);
    const dd = document.createElement('dd');
    dd.dataset['stat'] = key;
    dd.append(value);
    if (note) {
      const small = document.createElement('small');
      small.textContent = note;
      dd.append(' ', small);
    }
    if (key === 'cones') dd.dataset['testid'] = 'cone-count';
    if (key === 'flipped' && m.flipped > 0) item.className = 'warn';
    item.append(dt, dd);
    return item;
  });
}

/** Takes `run` and its figures `f`; returns the table of every other figure (mesh, settings, residuals, timings) for the details section. */
function statsTable(run: Run, f: ResultHook): HTMLDListElement {
  const { mesh: m, result: r, settings } = run;
  const report = m.data.report;
  const genus = report?.genus?.length ? report.genus.join(', ') : '—';
  const rows: Array<[string, string]> = [
    ['α smooth', fmtAlpha(settings.alpha_smooth)],
    ['Rounding', settings.miq ? 'MIQ emulation' : 'greedy'],
    ['Boundary', settings.boundary],
    ['Vertices', fmtInt(m.data.positions.length / 3)],
    ['Faces', fmtInt(m.data.indices.length / 3)],
    ['Genus', genus],
    ['Boundary loops', report ? fmtInt(report.boundary_loops) : '—'],
    ['Features', fmtInt(r.feature_edges)],
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
    ['Max distortion (face)', fmt(metrics.max_distortion)],
    ['Faces < 0.2 / < 0.3', `${fmt(metrics.fraction_below_0_2 * 100, 1)} % / ${fmt(metrics.fraction_below_0_3 * 100, 1)} %`],
    ['Seam length', fmt(metrics.seam_length)],
    ['Seam residual (angle / length)', `${fmt(metrics.seam_angle_residual)} / ${fmt(metrics.seam_length_residual)}`],
    ['Alignment residual', fmt(metrics.alignment_residual)],
  );
  if (r.inserted_vertices > 0) rows.push(['Inserted vertices (refinement)', fmtInt(r.inserted_vertices)]);
  const alignment = r.feature_alignment;
  if (alignment.requested > 0) {
    const off = alignment.unaligned.slice(0, 5).map((u) => `(v${u.vertices[0]}, v${u.vertices[1]}) ${u.degrees.toFixed(1)}°`).join(', ');
    rows.push(['Features on isolines', `${fmtInt(alignment.aligned)} / ${fmtInt(alignment.requested)}${off ? ` — off: ${off}` : ''}`]);
  }
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
  rows.push(['Time in worker', fmtMs(r.elapsed)]);
  return definitionList(rows);
}

/** The UV layout of the integer-grid map `uv` of `run` (its chart outlines along the same seams), coloured by `colors` (the seamless map's distortion, as in the 3D view). */
function gridLayout({ mesh: m, result: r }: Run, uv: Float32Array, colors: Float32Array | null): UvLayout {
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
