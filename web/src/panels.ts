// The left panel: status line with progress, error box, stats table, samples
// menu. Pure DOM; no knowledge of the worker or the viewer (the problems list
// is mesh-problems.ts).
import { $, definitionList, fmtBytes, fmtInt, fmtMs } from './dom';
import type { MeshReport } from './protocol';

export interface Stats {
  file: string;
  bytes: number;
  vertices: number;
  faces: number;
  importMs: number;
  report: MeshReport | null;
}

export interface Sample {
  name: string;
  file: string;
  bytes: number;
  note?: string;
}

/** Genus per component; '—' where the component is not manifold (genus undefined there). */
function genusText(r: MeshReport): string {
  if (!r.genus?.length) return '—';
  const shown = r.genus.slice(0, 8).map((g, i) => (r.component_is_manifold?.[i] === false ? '—' : String(g)));
  return shown.join(', ') + (r.genus.length > shown.length ? ', …' : '');
}

export class Panels {
  private readonly status = $('status');
  private readonly statusText = $('status-text');
  private readonly progress = $<HTMLProgressElement>('progress');
  private readonly error = $('error');
  private readonly stats = $('stats');
  readonly samples = $<HTMLSelectElement>('samples');

  setStatus(text: string, busy: boolean, fraction?: number): void {
    this.statusText.textContent = text;
    this.status.classList.toggle('busy', busy);
    if (busy && fraction !== undefined) {
      this.progress.hidden = false;
      this.progress.value = Math.max(0, Math.min(1, fraction));
    } else if (busy) {
      this.progress.hidden = false;
      this.progress.removeAttribute('value'); // indeterminate
    } else {
      this.progress.hidden = true;
    }
  }

  showError(file: string, message: string): void {
    this.error.replaceChildren();
    const title = document.createElement('strong');
    title.textContent = `Could not load ${file}`;
    const body = document.createElement('div');
    body.className = 'error-message';
    body.textContent = message;
    this.error.append(title, body);
    this.error.hidden = false;
  }

  clearError(): void {
    this.error.hidden = true;
    this.error.replaceChildren();
  }

  showStats(s: Stats): void {
    const rows: Array<[string, string]> = [
      ['File', s.file],
      ['Size', fmtBytes(s.bytes)],
      ['Vertices', fmtInt(s.report?.vertices ?? s.vertices)],
      ['Faces', fmtInt(s.report?.faces ?? s.faces)],
    ];
    const r = s.report;
    if (r) {
      rows.push(
        ['Boundary loops', fmtInt(r.boundary_loops)],
        ['Components', fmtInt(r.components)],
        ['Euler characteristic', String(r.euler_characteristic)],
        ['Genus', genusText(r)],
      );
      const optional: Array<[string, number | undefined]> = [
        ['Edges', r.edges],
        ['Boundary edges', r.boundary_edges],
        ['Non-manifold edges', r.non_manifold_edges],
        ['Merged vertices', r.merged_vertices],
      ];
      for (const [k, v] of optional) if (typeof v === 'number') rows.push([k, fmtInt(v)]);
    }
    rows.push(['Import time', fmtMs(s.importMs)]);
    this.stats.replaceChildren(definitionList(rows));
  }

  setSamples(samples: Sample[], selected: string): void {
    this.samples.replaceChildren();
    const placeholder = new Option('Load a sample…', '');
    placeholder.disabled = true;
    this.samples.append(placeholder);
    for (const s of samples) {
      const label = `${s.name}  (${fmtBytes(s.bytes)})${s.note ? ` — ${s.note}` : ''}`;
      this.samples.append(new Option(label, s.file, false, s.file === selected));
    }
  }
}
