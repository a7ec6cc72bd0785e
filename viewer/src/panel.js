// The page around the 3D view: title and counts, colouring and layer switches, the class legend
// (or the sessions' when the map is coloured by session), the frame slider with its play button,
// the selected localization and the list of all of them.
import { classColor, css, ERROR_STOPS, errorColor, sessionColor } from './colors.js';

const $ = (id) => document.getElementById(id);
const fmt = (v, digits = 2) => (v === null || v === undefined ? '–' : v.toFixed(digits));

function element(tag, attributes = {}, text = '') {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attributes)) e.setAttribute(k, v);
  if (text) e.textContent = text;
  return e;
}

// A localization's frame as the dataset names it (its scan's number, when it has one), with
// the run's index beside it; older scenes have no dataset_frame.
export function frameName(r) {
  const own = r.dataset_frame === null || r.dataset_frame === undefined ? null : r.dataset_frame;
  return own === null ? `${r.frame}` : `${own} (run ${r.frame})`;
}

function swatch(rgb) {
  return element('span', { class: 'swatch', style: `background:${css(rgb)}` });
}

// Heading in degrees about +z of a quaternion (x, y, z, w).
function yawDeg([x, y, z, w]) {
  return (Math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)) * 180) / Math.PI;
}

export class Panel {
  constructor(scene, viewer) {
    this.scene = scene;
    this.viewer = viewer;
    this.records = scene.localization ? scene.localization.records : [];
    this.selected = null;
    $('title').textContent = scene.title || scene.map.name;
    document.title = `${$('title').textContent} · semsegmap view`;
    this.showStats();
    this.buildColouring();
    this.buildLayers();
    this.buildLegend();
    this.buildSessionLegend();
    this.showLegendOf(this.viewer.mapColouring);
    this.buildErrorLegend();
    if (!scene.localization) return $('side').remove();  // nothing to step through or select
    this.buildList();
    this.buildPlayer();
    this.select(null);
  }

  showStats() {
    const s = this.scene;
    const stats = $('stats');
    stats.dataset.segments = s.map.count;
    stats.dataset.localizations = this.records.length;
    const parts = [`${s.map.count} map segments`];
    if (s.sessions.length > 1) parts.push(`${s.sessions.length} sessions`);
    if (s.map.points) parts.push(`${s.map.points.positions.length / 3} stored points`);
    if (s.localization) parts.push(`${this.records.length} localizations`);
    if (s.segments) parts.push(`${s.segments.segments} segments of ${s.segments.name}`);
    if (s.slam) parts.push(`${s.slam.loops.length} loop closures`);
    stats.textContent = parts.join(' · ');
  }

  buildColouring() {
    const select = $('colouring');
    const modes = ['class', 'segment', 'session'].concat(this.scene.segments ? ['camera'] : []);
    for (const m of modes) select.append(element('option', { value: m }, m));
    select.value = this.viewer.colouring;
    select.addEventListener('change', () => this.setColouring(select.value));
  }

  setColouring(mode) {
    $('colouring').value = mode;
    this.viewer.setColouring(mode);
    this.showLegendOf(this.viewer.mapColouring);
  }

  // The legend of what the map's colours mean: its sessions when coloured by session, else its
  // classes.
  showLegendOf(mapColouring) {
    $('session-legend').hidden = mapColouring !== 'session';
    $('class-legend').hidden = mapColouring === 'session';
  }

  buildLayers() {
    const box = $('layers');
    for (const name of Object.keys(this.viewer.layers)) {
      if (name === 'matches') continue;
      const input = element('input', { type: 'checkbox', 'data-layer': name });
      input.checked = true;
      input.addEventListener('change', () => this.viewer.setVisible(name, input.checked));
      const label = element('label');
      label.append(input, ` ${name}`);
      box.append(label);
    }
  }

  // The classes of the map's segments, most frequent first.
  buildLegend() {
    const counts = new Map();
    for (const c of this.scene.map.classes) counts.set(c, (counts.get(c) || 0) + 1);
    const legend = $('legend');
    for (const [id, n] of [...counts].sort((a, b) => b[1] - a[1])) {
      const c = this.scene.classes.get(id);
      const item = element('li', { 'data-class': id });
      item.append(swatch(classColor(this.scene.classes, id)), ` ${c ? c.name : `class ${id}`} `,
                  element('span', { class: 'count' }, String(n)));
      legend.append(item);
    }
  }

  // The sessions the map was merged from, in order (the map of one run: "this run"), with their
  // numbers of entries.
  buildSessionLegend() {
    const legend = $('sessions');
    this.scene.sessions.forEach((s, k) => {
      const item = element('li', { 'data-session': k });
      item.append(swatch(sessionColor(k)), ' ', element('span', { class: 'name' }, s.name), ' ',
                  element('span', { class: 'count' }, String(s.entries)));
      legend.append(item);
    });
  }

  buildErrorLegend() {
    const box = $('error-legend');
    if (!this.scene.localization) return box.remove();
    if (!this.scene.localization.has_ground_truth) {
      box.append(swatch(errorColor(null)), ' localization (no ground truth: error unknown)');
      return;
    }
    const stops = ERROR_STOPS.map(([e, c]) => `${css(c)} ${(e / 5) * 100}%`).join(',');
    box.append(element('div', { class: 'ramp', style: `background:linear-gradient(to right,${stops})` }),
               element('div', { class: 'ramp-labels' }, '0 m        1        2              5+ m'));
  }

  buildList() {
    const list = $('localizations');
    if (!this.records.length) return list.append(element('li', {}, 'no localization'));
    this.items = this.records.map((r, i) => {
      const item = element('li', { 'data-index': i });
      item.append(swatch(errorColor(r.error_m)),
                  ` frame ${frameName(r)} · ${r.inliers} inliers · ${r.error_m === null ? '?' : fmt(r.error_m)} m`);
      item.addEventListener('click', () => this.choose(i));
      list.append(item);
      return item;
    });
  }

  // The slider runs over the trajectory's frames (or the localizations' when there is none).
  buildPlayer() {
    const t = this.scene.localization && this.scene.localization.trajectory;
    this.frames = t ? t.frames : this.records.map((r) => r.frame);
    const slider = $('frame');
    if (!this.frames.length) return $('player').remove();
    slider.max = this.frames.length - 1;
    slider.addEventListener('input', () => this.setRow(Number(slider.value)));
    $('play').addEventListener('click', () => this.togglePlay());
    this.setRow(0);
  }

  togglePlay() {
    if (this.timer) {
      clearInterval(this.timer);
      this.timer = null;
      $('play').textContent = '▶';
      return;
    }
    $('play').textContent = '❚❚';
    if (this.row >= this.frames.length - 1) this.setRow(0);  // from the start again
    const step = Math.max(1, Math.round(this.frames.length / 600));  // a run in about 30 s
    this.timer = setInterval(() => {
      const next = this.row + step;
      if (next >= this.frames.length) return this.togglePlay();
      this.setRow(next);
    }, 50);
  }

  // Moves to trajectory row `row`: the robot there, and the latest localization at or before it.
  setRow(row) {
    this.row = row;
    $('frame').value = row;
    const frame = this.frames[row];
    $('frame-label').textContent = `frame ${frame}`;
    this.viewer.showRobot(...this.robotAt(row));
    let latest = null;
    this.records.forEach((r, i) => { if (r.frame <= frame) latest = i; });
    if (latest !== this.selected) this.select(latest);
  }

  robotAt(row) {
    const t = this.scene.localization && this.scene.localization.trajectory;
    if (!t) return [null, null];
    const first = t.estimateFirstRow;
    const [track, index] = t.estimate.length && row >= first ? [t.estimate, row - first]
      : t.groundTruth ? [t.groundTruth, row] : [null, 0];
    if (!track || 3 * index + 2 >= track.length) return [null, null];
    const p = Array.from(track.slice(3 * index, 3 * index + 3));
    const q = track.slice(3 * (index + 1), 3 * (index + 1) + 3);
    const heading = q.length === 3 && (q[0] !== p[0] || q[1] !== p[1]) ? [q[0] - p[0], q[1] - p[1], 0] : null;
    return [p, heading];
  }

  // A localization the user picked (in the list or on the canvas): the slider goes to its frame.
  choose(i) {
    const row = this.frames ? this.frames.indexOf(this.records[i].frame) : -1;
    if (row >= 0) {
      this.row = row;
      $('frame').value = row;
      $('frame-label').textContent = `frame ${this.frames[row]}`;
      this.viewer.showRobot(...this.robotAt(row));
    }
    this.select(i, true);
  }

  select(i, scroll = false) {
    this.selected = i;
    this.viewer.select(i);
    if (this.items) this.items.forEach((item, k) => item.classList.toggle('selected', k === i));
    const box = $('selection');
    box.replaceChildren();
    if (i === null) {
      box.dataset.index = '';
      box.dataset.matches = 0;
      box.append(element('p', { class: 'hint' }, this.records.length
        ? 'Click a localization (a disc on the path, or in the list) to see its matches.' : ''));
      return;
    }
    if (scroll) this.items[i].scrollIntoView({ block: 'nearest' });
    this.describe(box, i);
  }

  describe(box, i) {
    const r = this.records[i];
    box.dataset.index = i;
    box.dataset.matches = r.matches.length;
    const o = this.scene.origin;
    const rows = [
      ['frame', frameName(r)],
      ['time', r.time === null || r.time === undefined ? 'unknown (not in the data)' : `${fmt(r.time, 3)} s`],
      ['inliers', `${r.inliers}`],
      ['matches shown', this.scene.localization.has_matches ? `${r.matches.length}` : 'none (no matches.csv)'],
      ['position', r.position.map((v, k) => fmt(v + o[k], 2)).join(', ') + ' m'],
      ['heading', `${fmt(yawDeg(r.quaternion), 1)}°`],
      ['error', r.error_m === null ? 'unknown (no ground truth)' : `${fmt(r.error_m)} m, ${fmt(r.error_deg, 2)}°`],
    ];
    if (r.refinement_m !== null) rows.push(['refined by', `${fmt(r.refinement_m)} m`]);
    const table = element('table');
    for (const [k, v] of rows) {
      const tr = element('tr');
      tr.append(element('th', {}, k), element('td', {}, v));
      table.append(tr);
    }
    box.append(element('h2', {}, `Localization ${i + 1} of ${this.records.length}`), table,
               element('p', { class: 'hint' }, 'yellow: to each matched target segment (magenta); cyan: the local segments carried into the map by this pose, white to their targets'));
  }
}
