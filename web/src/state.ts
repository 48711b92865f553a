// The page's state, in one store: the phase the page is in, the token of the
// newest load (results of older loads are stale), whether a finished solve is
// being put on screen, where the quads of the solved map stand, and the solve
// tuning the test hooks set. Phases change only through `transition`, which
// rejects the changes that make no sense and tells the subscribers of every
// change. Pure: no DOM, no worker.

export type Phase = 'idle' | 'loading' | 'ready' | 'solving' | 'solved' | 'error';

/**
 * The quads of the solved map: none asked for (or quad mode off), being
 * computed, shown, or the last request failed (the map stays shown). Anything
 * but 'off' only in phase `solved`.
 */
export type QuadsPhase = 'off' | 'running' | 'shown' | 'failed';

/** How a solve is spread over workers and how hard it tries (the tests change these through `window.__conemapTest`). */
export interface SolveTuning {
  /** Meshes with fewer faces solve in one worker: a helper's start-up (wasm, import) would cost more than it saves. */
  helperMinFaces: number;
  /** The main worker waits until the helper is ready, so that both surely place components. */
  helperWait: boolean;
  /** Refinements around cones of angle 0 before a solve fails (undefined: the library's default). */
  maxConeRefinements: number | undefined;
}

export interface PageState {
  readonly phase: Phase;
  /** Token of the newest load (0 before the first): a load holding an older one is stale. */
  readonly load: number;
  /** Only while solving: the solver has answered and its result is being put on screen. */
  readonly building: boolean;
  /** Where the quads of the solved map stand; 'off' outside `solved`. */
  readonly quads: QuadsPhase;
  readonly tuning: Readonly<SolveTuning>;
}

/** The phases each phase may go to. A failed load keeps the previous mesh open, so `error` may go on to `solving`; a load first ends a running solve. */
const NEXT: Readonly<Record<Phase, readonly Phase[]>> = {
  idle: ['loading'],
  loading: ['loading', 'ready', 'error'],
  ready: ['loading', 'solving'],
  solving: ['solving', 'ready', 'solved'],
  solved: ['loading', 'solving'],
  error: ['loading', 'solving'],
};

/** Thrown by `transition` for a change of phase that makes no sense. */
export class InvalidTransition extends Error {
  override name = 'InvalidTransition';
}

export type Listener = (state: PageState) => void;

/** True when a page in phase `from` may go to phase `to`. */
export const canTransition = (from: Phase, to: Phase): boolean => NEXT[from].includes(to);

export class PageStore {
  private current: PageState = {
    phase: 'idle',
    load: 0,
    building: false,
    quads: 'off',
    tuning: { helperMinFaces: 50_000, helperWait: false, maxConeRefinements: undefined },
  };
  private readonly listeners = new Set<Listener>();

  /** The state as it is now (a new object after every change; never mutated). */
  get state(): PageState {
    return this.current;
  }

  /**
   * Goes to phase `to` (with `building`: solving and putting the result on
   * screen); throws `InvalidTransition` when `to` cannot follow the current
   * phase, or `building` is asked for outside `solving`. Leaving `solved`
   * turns the quads 'off'. Notifies the subscribers.
   */
  transition(to: Phase, { building = false }: { building?: boolean } = {}): void {
    this.check(to, building);
    this.set({ phase: to, building, ...(to === 'solved' ? {} : { quads: 'off' as const }) });
  }

  /**
   * Sets where the quads stand (see `QuadsPhase`); throws `InvalidTransition`
   * for anything but 'off' outside phase `solved`. Notifies the subscribers
   * when it changes.
   */
  setQuads(quads: QuadsPhase): void {
    if (quads !== 'off' && this.current.phase !== 'solved') throw new InvalidTransition(`quads need a solved map, not ${this.current.phase}`);
    if (quads !== this.current.quads) this.set({ quads });
  }

  /** Starts a load: goes to `loading` (see `transition`: the quads go 'off') and returns its token, which makes every earlier token stale. */
  beginLoad(): number {
    this.check('loading', false);
    this.set({ phase: 'loading', building: false, quads: 'off', load: this.current.load + 1 });
    return this.current.load;
  }

  /** True while `token` (from `beginLoad`) is the newest load's. */
  isCurrentLoad(token: number): boolean {
    return token === this.current.load;
  }

  /** Changes the fields of `patch` in the solve tuning; notifies the subscribers. */
  setTuning(patch: Partial<SolveTuning>): void {
    this.set({ tuning: { ...this.current.tuning, ...patch } });
  }

  /** Calls `listener` with the state now, then with the new state after every change; returns the unsubscribe function. */
  subscribe(listener: Listener): () => void {
    this.listeners.add(listener);
    listener(this.current);
    return () => this.listeners.delete(listener);
  }

  /** Throws `InvalidTransition` unless the current phase may go to `to` (with `building` only when `to` is solving). */
  private check(to: Phase, building: boolean): void {
    const from = this.current.phase;
    if (!canTransition(from, to)) throw new InvalidTransition(`the page cannot go from ${from} to ${to}`);
    if (building && to !== 'solving') throw new InvalidTransition(`only a solve builds a view, not ${to}`);
  }

  private set(patch: Partial<PageState>): void {
    this.current = { ...this.current, ...patch };
    for (const listener of [...this.listeners]) listener(this.current);
  }
}

/**
 * Mirrors `store` into the data attributes of `dataset` (the page's body):
 * `state` = the phase, `solving` = 'true' while solving, `quads` = the quads
 * phase unless 'off'.
 */
export function mirrorToDataset(store: PageStore, dataset: DOMStringMap): () => void {
  return store.subscribe(({ phase, quads }) => {
    dataset['state'] = phase;
    if (phase === 'solving') dataset['solving'] = 'true';
    else delete dataset['solving'];
    if (quads !== 'off') dataset['quads'] = quads;
    else delete dataset['quads'];
  });
}
