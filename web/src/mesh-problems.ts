// The problems of the mesh as read: the Problems list in the side panel (the
// library's messages, elements numbered as the file does), every offending
// edge, face and vertex drawn in the 3D view, and a click on a line framing
// that problem. Nothing here parses messages: the library locates them.
import { $ } from './dom';
import { COLORS } from './palette';
import type { ImportResult, LocatedProblem } from './protocol';
import type { Hooks } from './test-hooks';
import type { Viewer } from './viewer';

/** Lines listed at most (the rest are counted). */
const SHOWN = 100;

/** The edges `p` names and the sides of its faces (triangles of `data`), as vertex pairs (flat; only vertices `data` has). */
function problemPairs(p: LocatedProblem, data: ImportResult): number[] {
  const { indices, positions } = data;
  const out = [...p.edges];
  for (const f of p.faces) {
    if (3 * f + 2 >= indices.length) continue;
    const [a, b, c] = [indices[3 * f]!, indices[3 * f + 1]!, indices[3 * f + 2]!];
    out.push(a, b, b, c, c, a);
  }
  const n = positions.length / 3;
  const valid: number[] = [];
  for (let i = 0; i + 1 < out.length; i += 2) if (out[i]! < n && out[i + 1]! < n) valid.push(out[i]!, out[i + 1]!);
  return valid;
}

/** Ids `0 .. n-1`. */
const range = (n: number): number[] => Array.from({ length: n }, (_, i) => i);

export class MeshProblems {
  private problems: LocatedProblem[] = [];
  private data: ImportResult | null = null;
  private selected: HTMLButtonElement | null = null;
  private readonly section = $('problems');

  constructor(
    private readonly viewer: Viewer,
    private readonly hooks: Pick<Hooks, 'problemFocus'>,
  ) {}

  /** The problems that block solving the open mesh. */
  get blocking(): LocatedProblem[] {
    return this.problems.filter((p) => p.blocking);
  }

  /** Lists the problems of the freshly shown mesh `data` and draws them all in the 3D view. */
  show(data: ImportResult): void {
    this.data = data;
    this.problems = data.report?.located_problems ?? [];
    this.selected = null;
    this.hooks.problemFocus = null;
    this.render();
    this.draw();
  }

  private render(): void {
    const r = this.data?.report;
    this.section.replaceChildren();
    this.section.hidden = !r;
    if (!r) return;
    const heading = document.createElement('h2');
    heading.textContent = 'Problems';
    const all = this.problems;
    if (all.length === 0) {
      const ok = document.createElement('p');
      ok.className = 'ok';
      ok.textContent = 'None found.';
      this.section.append(heading, ok);
      return;
    }
    heading.textContent = `Problems (${all.length})`;
    const hint = document.createElement('p');
    hint.className = 'hint';
    hint.textContent = 'Drawn in the 3D view; click one to frame it. Numbers as in the file.';
    const list = document.createElement('ul');
    list.dataset['testid'] = 'problem-list';
    all.slice(0, SHOWN).forEach((p, i) => {
      const li = document.createElement('li');
      const button = document.createElement('button');
      button.type = 'button';
      button.className = `problem-line${p.blocking ? ' blocking' : ''}`;
      button.dataset['testid'] = 'problem-line';
      button.textContent = p.message;
      button.title = p.blocking ? 'Blocks solving: click to frame it in the 3D view' : 'Repaired on import: click to frame it in the 3D view';
      button.addEventListener('click', () => this.focus(i, button));
      li.append(button);
      list.append(li);
    });
    if (all.length > SHOWN) {
      const li = document.createElement('li');
      li.className = 'more';
      li.textContent = `… and ${all.length - SHOWN} more`;
      list.append(li);
    }
    this.section.append(heading, hint, list);
  }

  /** Draws every problem's edges and face outlines, and markers on the vertices of those without either. */
  private draw(): void {
    const pairs: number[] = [];
    if (this.data) for (const p of this.problems) pairs.push(...problemPairs(p, this.data));
    this.viewer.setLines('mesh-problems', Uint32Array.from(pairs), range(pairs.length / 2), COLORS.problem, 4, 3);
    this.viewer.setProblemVertices(this.problems.filter((p) => p.edges.length === 0 && p.faces.length === 0).flatMap((p) => p.vertices));
    this.viewer.setLines('problem-focus', new Uint32Array(0), [], COLORS.hover);
  }

  /** Problem `i` (its line `button`) highlighted over the rest and framed in the 3D view. */
  private focus(i: number, button: HTMLButtonElement): void {
    const p = this.problems[i];
    if (!p || !this.data) return;
    this.selected?.classList.remove('selected');
    this.selected = button;
    button.classList.add('selected');
    const pairs = problemPairs(p, this.data);
    this.viewer.setLines('problem-focus', Uint32Array.from(pairs), range(pairs.length / 2), COLORS.hover, 6, 4);
    const vertices = [...new Set([...p.vertices, ...pairs])];
    // Markers only where no line shows the problem (they are sized for the whole mesh).
    this.viewer.setProblemVertices(pairs.length === 0 ? p.vertices : []);
    this.viewer.frameOn(vertices);
    this.hooks.problemFocus = { index: i, vertices };
  }
}
