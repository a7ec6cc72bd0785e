// semsegmap view's page: reads the scene embedded in the file, builds the 3D view and the panel,
// and exposes window.semsegmapViewer for scripts and tests (README.md).
import { classColor, sessionColor } from './colors.js';
import { decodeScene } from './scene.js';
import { Viewer } from './view3d.js';
import { Panel } from './panel.js';

const api = { ready: false, error: null };
window.semsegmapViewer = api;

function fail(message) {
  api.error = message;
  const box = document.getElementById('message');
  box.textContent = message;
  box.hidden = false;
}

// A click that did not drag the view picks the localization under it.
function listenForPicks(canvas, viewer, panel) {
  let down = null;
  canvas.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
  canvas.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 5) return;
    const i = viewer.pick(e.clientX, e.clientY);
    if (i !== null) panel.choose(i);
  });
}

function expose(scene, viewer, panel) {
  const records = scene.localization ? scene.localization.records : [];
  Object.assign(api, {
    stats: {
      segments: scene.map.count,
      mapPoints: scene.map.points ? scene.map.points.positions.length / 3 : 0,
      localizations: records.length,
      matches: records.reduce((n, r) => n + r.matches.length, 0),
      segmentRunSegments: scene.segments ? scene.segments.segments : 0,
      segmentRunPoints: scene.segments ? scene.segments.points.positions.length / 3 : 0,
      loops: scene.slam ? scene.slam.loops.length : 0,
      sessions: scene.sessions.length,
      frames: panel.frames ? panel.frames.length : 0,
    },
    layers: () => Object.keys(viewer.layers),
    selected: () => (panel.selected === null ? null
      : { index: panel.selected, frame: records[panel.selected].frame, matches: viewer.shownMatches }),
    select: (i) => panel.choose(i),
    setRow: (row) => panel.setRow(row),
    setColouring: (mode) => panel.setColouring(mode),
    mapColours: () => viewer.mapColours(),
    sessionColour: (i) => sessionColor(i),
    sessionTrajectories: () => viewer.shownSessionTrajectories(),
    screenPositionOfLocalization: (i) => viewer.screenPosition(records[i].position),
    matchesOf: (i) => records[i].matches.length,
    classColour: (id) => classColor(scene.classes, id),
    measureRotation: (ms) => viewer.measureRotation(ms),
    rendered: () => viewer.frames || 0,
  });
}

function boot() {
  const started = performance.now();
  const text = document.getElementById('semsegmap-scene').textContent;
  let json;
  try {
    json = JSON.parse(text);
  } catch {
    return fail('This is the viewer page without a scene: write one with `semsegmap view`.');
  }
  const parsed = performance.now();
  const scene = decodeScene(json);
  const decoded = performance.now();
  const canvas = document.getElementById('view');
  const viewer = new Viewer(canvas, scene);
  const panel = new Panel(scene, viewer);
  listenForPicks(canvas, viewer, panel);
  expose(scene, viewer, panel);
  const built = performance.now();
  requestAnimationFrame(() => {
    viewer.render();
    api.phasesMs = { parse: parsed - started, decode: decoded - parsed, build: built - decoded,
                     firstFrame: performance.now() - built };
    // Since the page began to load: reading the file, parsing, building and the first frame.
    api.loadMs = performance.now();
    api.buildMs = api.loadMs - started;
    api.ready = true;
    document.body.dataset.ready = 'true';
  });
}

try {
  boot();
} catch (e) {
  fail(`The scene cannot be shown: ${e.message}`);
  throw e;
}
