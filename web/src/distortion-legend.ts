// The legend of the Distortion surface: what is measured (the isometric
// distortion of the paper's eq. 19, per face), the scale control — auto (each
// result's 99th percentile) or a fixed value kept across runs, so that two
// runs compare — the viridis ramp with its 0 and scale labels, and the
// histogram whose last bar holds every face at or above the scale.
import { $, fmt } from './dom';
import { rampGradient } from './palette';
import { rampCss } from './solve-view';

/** The share of the histogram's width its last bar (≥ scale) takes, apart from the others (also the ramp's and the labels'). */
const OVERFLOW_WIDTH = 0.16;
/** The colour of the histogram's bars up to the scale (the ramp above them keys the colours); the last bar has the ramp's top colour. */
const BAR_COLOR = '#9aa9bf';

export class DistortionLegend {
  /** Called when the scale changes (mode, or a valid fixed value). */
  onChange: (() => void) | null = null;
  private readonly el = {
    box: $('distortion-legend'),
    mode: $<HTMLSelectElement>('distortion-scale-mode'),
    value: $<HTMLInputElement>('distortion-scale-value'),
    ramp: $('distortion-ramp'),
    max: $('distortion-max'),
    histogram: $<HTMLCanvasElement>('histogram'),
  };
  /** The scale of the histogram drawn last (prefills the fixed value). */
  private drawnMax = 1;

  /** Wires the scale controls and paints the ramp. */
  constructor() {
    const el = this.el;
    el.ramp.style.background = rampGradient(1 - OVERFLOW_WIDTH);
    el.box.style.setProperty('--overflow-width', `${OVERFLOW_WIDTH * 100}%`);
    el.mode.addEventListener('change', () => {
      const fixed = el.mode.value === 'fixed';
      el.value.disabled = !fixed;
      if (fixed && !(Number(el.value.value) > 0)) el.value.value = String(roundScale(this.drawnMax));
      this.onChange?.();
    });
    el.value.addEventListener('change', () => {
      if (Number(el.value.value) > 0) this.onChange?.();
      else el.value.value = String(roundScale(this.drawnMax)); // back to a valid value, nothing changes
    });
  }

  /** The fixed scale asked for, or undefined for auto (each result's 99th percentile). */
  get fixedScale(): number | undefined {
    const v = Number(this.el.value.value);
    return this.el.mode.value === 'fixed' && v > 0 ? v : undefined;
  }

  /** Draws scale `max` and the histogram `counts` (see HISTOGRAM_BINS: the last bin is every face ≥ max). */
  draw(max: number, counts: Uint32Array): void {
    this.drawnMax = max;
    this.el.max.textContent = fmt(max);
    const canvas = this.el.histogram;
    const g = canvas.getContext('2d')!;
    const bins = counts.length;
    const top = Math.max(...counts, 1);
    const h = canvas.height - 4;
    g.clearRect(0, 0, canvas.width, canvas.height);
    const span = canvas.width * (1 - OVERFLOW_WIDTH);
    const w = span / (bins - 1);
    g.fillStyle = BAR_COLOR;
    for (let i = 0; i < bins - 1; i++) {
      const bar = (counts[i]! / top) * h;
      g.fillRect(i * w + 0.5, canvas.height - bar, Math.max(w - 1, 1), bar);
    }
    // The last bar, apart: everything at or above the scale.
    const gap = canvas.width * 0.02;
    const over = (counts[bins - 1]! / top) * h;
    g.fillStyle = rampCss(1);
    g.fillRect(span + gap, canvas.height - over, canvas.width - span - gap, over);
    const share = counts.reduce((s, c) => s + c, 0);
    canvas.setAttribute('aria-label', `Histogram of per-face distortion: ${counts[bins - 1]} of ${share} faces at or above ${fmt(max)}`);
  }
}

/** A scale rounded to two significant digits (the fixed value a switch to fixed starts from). */
export function roundScale(x: number): number {
  return x > 0 ? Number(x.toPrecision(2)) : 1;
}
