// Element lookup, definition tables and the number / size / time formatting the
// page's panels share. No state; the formatters are pure.
import { GLOSSARY } from './glossary';

/** The element of index.html with id `id` (as `T`); throws when the page lacks it. */
export const $ = <T extends HTMLElement = HTMLElement>(id: string): T => {
  const el = document.getElementById(id);
  if (!el) throw new Error(`#${id} missing from index.html`);
  return el as T;
};

/** `x` with `digits` decimals; exponential when |x| ≥ 1e4 or 0 < |x| < 1e-3; '—' when not finite. */
export const fmt = (x: number, digits = 3): string =>
  !Number.isFinite(x) ? '—' : Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-3 && x !== 0) ? x.toExponential(2) : x.toFixed(digits);

/** A count with thousands separators (en-US); '—' when `n` is not a number. */
export const fmtInt = (n: number | undefined): string => (typeof n === 'number' ? n.toLocaleString('en-US') : '—');

/** A byte count in B, KB or MB (one decimal above 1 KB). */
export const fmtBytes = (n: number): string =>
  n < 1024 ? `${n} B` : n < 1024 ** 2 ? `${(n / 1024).toFixed(1)} KB` : `${(n / 1024 ** 2).toFixed(1)} MB`;

/** A duration in milliseconds, rounded: "12 ms". */
export const fmtMs = (ms: number): string => `${ms.toFixed(0)} ms`;

/** A duration for people: "640 ms" below a second, "3.2 s" below 100 s, "123 s" above; '—' when not finite. */
export const fmtDuration = (ms: number): string =>
  !Number.isFinite(ms) ? '—' : ms < 1000 ? fmtMs(ms) : ms < 100_000 ? `${(ms / 1000).toFixed(1)} s` : `${(ms / 1000).toFixed(0)} s`;

/** α_smooth as shown (fewer decimals for larger values). */
export const fmtAlpha = (a: number): string =>
  a >= 10 ? a.toFixed(0) : a >= 1 ? a.toFixed(2) : a >= 0.01 ? a.toFixed(3) : a.toExponential(1);

/** A two-column table of figures; each value carries `data-stat` (its key in kebab case), each jargon label its plain words as tooltip. */
export function definitionList(rows: Array<[string, string]>): HTMLDListElement {
  const table = document.createElement('dl');
  for (const [k, v] of rows) {
    const dt = termLabel(k);
    const dd = document.createElement('dd');
    dd.textContent = v;
    dd.dataset['stat'] = statKey(k);
    table.append(dt, dd);
  }
  return table;
}

/** A `dt` reading `label`; a jargon label carries its plain words (glossary.ts) as tooltip and the class `term`. */
export function termLabel(label: string): HTMLElement {
  const dt = document.createElement('dt');
  dt.textContent = label;
  const tip = GLOSSARY[label];
  if (tip) {
    dt.title = tip;
    dt.className = 'term';
  }
  return dt;
}

/** The `data-stat` key of a table row label: lower case, runs of other characters as one '-', none at the ends. */
export const statKey = (label: string): string => label.toLowerCase().replace(/[^a-z0-9]+/g, '-').replace(/^-|-$/g, '');
