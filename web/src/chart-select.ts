// Chart selection: a click on a chart (a connected UV island, see charts.ts)
// in the UV view selects it in both views (its faces highlighted in 3D and in
// the layout); a click on empty space, Escape or a new map clears it. The charts of a result are found on the first click.
import { type Charts, chartFaces, faceCharts } from './charts';
import type { Hooks } from './test-hooks';
import type { UvView } from './uvview';
import type { Viewer } from './viewer';

/** What a map's charts are found from: each face side's edge (≥ `edgeCount`: none) and the seams cut. */
export interface ChartSource {
  faceEdges: Uint32Array;
  edgeCount: number;
  seams: Uint32Array;
}

export class ChartSelection {
  private source: ChartSource | null = null;
  private charts: Charts | null = null;

  /** Selects in `viewer` and `uvView` on clicks in `uvView` (Escape clears); keeps `hooks.chart` up to date. */
  constructor(
    private readonly viewer: Viewer,
    private readonly uvView: UvView,
    private readonly hooks: Pick<Hooks, 'chart'>,
  ) {
    uvView.onSelect = (face) => this.selectFace(face);
    window.addEventListener('keydown', (e) => {
      if (e.key === 'Escape' && this.hooks.chart) this.selectFace(null);
    });
  }

  /** Takes the map shown (null: none); clears the selection. */
  setMap(source: ChartSource | null): void {
    this.source = source;
    this.charts = null;
    this.selectFace(null);
  }

  /** Highlights the selected chart again (in a new layout of the same map's faces). */
  reapply(): void {
    this.selectFace(this.hooks.chart?.face ?? null);
  }

  /** Selects the chart of face `face` in both views (null: clears the selection). */
  selectFace(face: number | null): void {
    const src = this.source;
    if (face !== null && src && !this.charts) this.charts = faceCharts(src.faceEdges, src.edgeCount, src.seams);
    const charts = this.charts;
    if (face === null || !charts || face >= charts.chartOf.length) {
      this.viewer.setSelectedFaces(null);
      this.uvView.setSelectedFaces(null);
      this.hooks.chart = null;
      return;
    }
    const chart = charts.chartOf[face]!;
    const faces = chartFaces(charts, chart);
    this.hooks.chart = {
      face, chart, charts: charts.offsets.length - 1,
      faces3d: this.viewer.setSelectedFaces(faces),
      facesUv: this.uvView.setSelectedFaces(faces),
    };
  }
}
