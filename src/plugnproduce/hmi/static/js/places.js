// Where a step lies in the task being edited. A place is a path of indices and outcomes: [2] is the
// third step of the task, [2, "NoPartFound", 0] the first step of that step's NoPartFound branch,
// and so on for branches in branches. Rows number every step in the order the task file writes
// them (a step, then its branches' steps), as the server numbers the editor's rows.

/** The list of steps a place's prefix ([] for the task, [i, outcome, ...] for a branch) names. */
export function listAt(steps, prefix) {
  let list = steps;
  for (let k = 0; k < prefix.length; k += 2) list = ((list[prefix[k]] || {}).on || {})[prefix[k + 1]] || [];
  return list;
}

/** The steps with the list at `prefix` replaced by `fn(list)`; an emptied branch goes away. */
export function withList(steps, prefix, fn) {
  if (prefix.length === 0) return fn(steps);
  const [i, outcome, ...rest] = prefix;
  const owner = steps[i];
  const on = { ...(owner.on || {}) };
  const inner = withList(on[outcome] || [], rest, fn);
  if (inner.length) on[outcome] = inner;
  else delete on[outcome];
  const copy = [...steps];
  const { on: _old, ...plain } = owner;
  copy[i] = Object.keys(on).length ? { ...plain, on } : plain;
  return copy;
}

/** The step at `place`. */
export function stepAt(steps, place) {
  return listAt(steps, place.slice(0, -1))[place[place.length - 1]];
}

/** The steps with the step at `place` replaced by `step` (added when the place is one past the end), or removed (null). */
export function withStep(steps, place, step) {
  const index = place[place.length - 1];
  return withList(steps, place.slice(0, -1), (list) => {
    const copy = [...list];
    if (step) copy.splice(index, index < copy.length ? 1 : 0, step);
    else copy.splice(index, 1);
    return copy;
  });
}

/** Every step in the order the task file writes them: [{row, step, place, depth}]. */
export function rowsOf(steps) {
  const out = [];
  const walk = (list, prefix, depth) => list.forEach((step, i) => {
    const place = [...prefix, i];
    out.push({ row: out.length, step, place, depth });
    for (const [outcome, inner] of Object.entries(step.on || {})) walk(inner, [...place, outcome], depth + 1);
  });
  walk(steps, [], 0);
  return out;
}

export const placeKey = (place) => place.join("/");

/** The row of the step at `place` (rows count every step, branches' steps included). */
export function rowOf(steps, place) {
  const key = placeKey(place);
  const found = rowsOf(steps).find((r) => placeKey(r.place) === key);
  return found ? found.row : -1;
}

/**
 * A step's number as the editor shows it: "3" for the third step of the task, "3.2" for the second
 * step of step 3's branches (counted through its branches in order), "3.2.1" deeper.
 */
export function numberOf(steps, place) {
  let text = String(place[0] + 1);
  let owner = steps[place[0]];
  for (let k = 1; k < place.length; k += 2) {
    let before = 0;
    for (const [outcome, inner] of Object.entries(owner.on || {})) {
      if (outcome === place[k]) break;
      before += inner.length;
    }
    text += `.${before + place[k + 1] + 1}`;
    owner = listAt([owner], [0, place[k]])[place[k + 1]] || {};
  }
  return text;
}

/**
 * The steps that have run on every path to `place` before it: [{step, place}]. Those earlier in its own
 * list and in each list it lies in, and each branch's owner; not the steps of other branches.
 */
export function earlierOnPath(steps, place) {
  const out = [];
  let list = steps;
  for (let k = 0; k < place.length; k += 2) {
    const prefix = place.slice(0, k);
    list.slice(0, place[k]).forEach((step, i) => out.push({ step, place: [...prefix, i] }));
    if (k + 1 < place.length) {
      out.push({ step: list[place[k]], place: place.slice(0, k + 1) });
      list = listAt(list, place.slice(k, k + 2));
    }
  }
  return out;
}
