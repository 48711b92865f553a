// The split between the 3D view and the UV pane: side by side when the area
// they share is wider than tall, stacked otherwise (narrow windows, phones),
// with a divider between them that sets the UV pane's share of the area: drag
// it, or focus it and use the arrow keys (Shift: finer steps), Home and End
// (the limits), double-click it for the default split — the ARIA
// window-splitter pattern, its value being the 3D view's share in percent.

/** Which way the panes are laid out: side by side ('row') or stacked ('column'). */
export type SplitAxis = 'row' | 'column';

/** The UV pane's share of the area at first. */
export const DEFAULT_SHARE = 0.42;

/** Fewest CSS pixels either pane keeps. */
export const MIN_PANE_PX = 140;

/** Share change per arrow key press (with Shift: FINE_STEP). */
const STEP = 0.05;
const FINE_STEP = 0.01;

/** The axis of an area `width` × `height`: side by side when it is at least as wide as tall. */
export function splitAxis(width: number, height: number): SplitAxis {
  return width >= height ? 'row' : 'column';
}

/** `share` limited so that both panes of an area `total` px long keep `minPx` (an even split when they cannot). */
export function clampShare(share: number, total: number, minPx = MIN_PANE_PX): number {
  if (!(total > 2 * minPx)) return 0.5;
  const lo = minPx / total;
  return Math.min(1 - lo, Math.max(lo, Number.isFinite(share) ? share : DEFAULT_SHARE));
}

export class SplitPane {
  private share = DEFAULT_SHARE;
  private axis: SplitAxis = 'row';

  /**
   * Lays out `area` (holding the 3D view, `divider` and `secondary` in that
   * order) as a split and wires the divider; `area.dataset.split` says the axis.
   */
  constructor(
    private readonly area: HTMLElement,
    private readonly divider: HTMLElement,
    private readonly secondary: HTMLElement,
  ) {
    const observer = new ResizeObserver(() => this.layout());
    observer.observe(area);
    observer.observe(divider); // shown with the UV pane: its size counts
    this.wireDrag();
    divider.addEventListener('keydown', (e) => this.key(e));
    divider.addEventListener('dblclick', () => this.setShare(DEFAULT_SHARE));
    this.layout();
  }

  /** The UV pane's share of the area (0..1). */
  get uvShare(): number {
    return this.share;
  }

  /** Sets the UV pane's share of the area beside the divider (limited, see `clampShare`) and applies it. */
  setShare(share: number): void {
    const { total, bar } = this.extent();
    this.share = clampShare(share, total);
    this.secondary.style.flexBasis = `calc((100% - ${bar}px) * ${this.share.toFixed(4)})`;
    const least = Math.round(clampShare(1, total) === 0.5 ? 50 : (MIN_PANE_PX / total) * 100);
    this.divider.setAttribute('aria-valuemin', String(least));
    this.divider.setAttribute('aria-valuemax', String(100 - least));
    this.divider.setAttribute('aria-valuenow', String(Math.round((1 - this.share) * 100)));
  }

  /** The length (CSS px) along the axis shared by the two panes, and the divider's. */
  private extent(): { total: number; bar: number } {
    const row = this.axis === 'row';
    const bar = row ? this.divider.offsetWidth : this.divider.offsetHeight;
    return { total: (row ? this.area.clientWidth : this.area.clientHeight) - bar, bar };
  }

  /** Picks the axis for the area's current size and applies the share. */
  private layout(): void {
    const { clientWidth: w, clientHeight: h } = this.area;
    if (w === 0 || h === 0) return;
    this.axis = splitAxis(w, h);
    this.area.dataset['split'] = this.axis;
    // The separator's own orientation: a vertical bar between panes side by side.
    this.divider.setAttribute('aria-orientation', this.axis === 'row' ? 'vertical' : 'horizontal');
    this.setShare(this.share);
  }

  /** Dragging the divider moves it with the pointer (captured, so that the canvases under it see nothing). */
  private wireDrag(): void {
    const d = this.divider;
    d.addEventListener('pointerdown', (e) => {
      if (e.button !== 0) return;
      e.preventDefault();
      d.setPointerCapture(e.pointerId);
      d.focus();
      this.area.classList.add('dragging');
    });
    d.addEventListener('pointermove', (e) => {
      if (!d.hasPointerCapture(e.pointerId)) return;
      // The divider's middle follows the pointer.
      const r = this.area.getBoundingClientRect();
      const { total, bar } = this.extent();
      this.setShare(((this.axis === 'row' ? r.right - e.clientX : r.bottom - e.clientY) - bar / 2) / total);
    });
    const end = (e: PointerEvent): void => {
      if (d.hasPointerCapture(e.pointerId)) d.releasePointerCapture(e.pointerId);
      this.area.classList.remove('dragging');
    };
    d.addEventListener('pointerup', end);
    d.addEventListener('pointercancel', end);
  }

  /** Arrow keys move the divider (left / up: the 3D view smaller), Home and End to the limits. */
  private key(e: KeyboardEvent): void {
    const step = e.shiftKey ? FINE_STEP : STEP;
    const to: Record<string, number> = {
      ArrowLeft: this.share + step, ArrowUp: this.share + step,
      ArrowRight: this.share - step, ArrowDown: this.share - step,
      Home: 1, End: 0,
    };
    const share = to[e.key];
    if (share === undefined) return;
    e.preventDefault();
    this.setShare(share);
  }
}
