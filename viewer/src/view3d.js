// The 3D scene: one THREE object per layer (map, the map's sessions' trajectories, segmentation
// run, trajectories, localizations, the selected localization's matches, the SLAM run), drawn
// only when something changed.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { discs, fillColors, setViewport } from './discs.js';
import { classColor, errorColor, segmentColor, sessionColor } from './colors.js';

const FOV = 50;
const MAP_COLOURINGS = ['class', 'segment', 'session'];

const hex = ([r, g, b]) => (r << 16) | (g << 8) | b;

function line(positions, color) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  return new THREE.Line(g, new THREE.LineBasicMaterial({ color }));
}

function segments(positions, color) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color }));
}

// Drawn over the map whatever is in front (trajectories, localizations, matches): what the
// page is about must not hide behind the segments it was matched to.
function onTop(object, order) {
  object.renderOrder = order;
  object.traverse((o) => { if (o.material) o.material.depthTest = false; });
  return object;
}

// Diameter of a map segment drawn as its centroid: grows with the square root of its points.
const centroidSize = (points) => Math.min(6, 0.4 + 0.06 * Math.sqrt(points));

export class Viewer {
  constructor(canvas, scene) {
    this.scene = scene;
    this.canvas = canvas;
    // Multisampling multiplies the work of every pixel: worth it for a small scene, not for a
    // million points on a machine that renders in software.
    const points = (scene.map.points ? scene.map.points.positions.length / 3 : scene.map.count) +
      (scene.segments ? scene.segments.points.positions.length / 3 : 0);
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: points < 300000,
                                              preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    this.three = new THREE.Scene();
    this.three.background = new THREE.Color(0x15171c);
    this.camera = new THREE.PerspectiveCamera(FOV, 1, 0.1, 20000);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.addEventListener('change', () => this.requestRender());
    this.layers = {};
    this.colouring = MAP_COLOURINGS.includes(scene.colouring) ? scene.colouring : 'class';
    this.mapColouring = this.colouring;  // the camera colouring leaves the map as it was
    this.buildMap();
    this.buildSessionTrajectories();
    this.buildSegmentRun();
    this.buildLocalizations();
    this.buildSlam();
    this.buildGrid();
    this.fitCamera();
    window.addEventListener('resize', () => this.resize());
    this.resize();
  }

  add(name, object) {
    this.layers[name] = object;
    this.three.add(object);
  }

  buildMap() {
    const m = this.scene.map;
    if (m.points) {
      const n = m.points.positions.length / 3;
      this.mapColors = new Uint8Array(3 * n);
      this.add('map', discs(m.points.positions, this.mapColors, 0.12, 1.5));
    } else {
      const sizes = Float32Array.from(m.sizes, centroidSize);
      this.mapColors = new Uint8Array(3 * m.count);
      this.add('map', discs(m.centroids, this.mapColors, sizes, 2));
    }
    this.colourMap();
  }

  colourMap() {
    const m = this.scene.map;
    const classes = this.scene.classes;
    const segmentOf = m.points ? (i) => m.points.group[i] : (i) => i;
    const sessionOf = m.sessions ? (s) => m.sessions[s] : () => 0;
    const n = this.mapColors.length / 3;
    fillColors(this.mapColors, n, (i) => {
      const s = segmentOf(i);
      if (this.mapColouring === 'segment') return segmentColor(s);
      if (this.mapColouring === 'session') return sessionColor(sessionOf(s));
      return classColor(classes, m.classes[s]);
    });
    this.layers.map.geometry.attributes.rgb.needsUpdate = true;
    if (this.sessionLines) this.sessionLines.visible = this.mapColouring === 'session';
  }

  // Each session's trajectory in its colour, shown while the map is coloured by session (the
  // first session has none: it defines the map's frame).
  buildSessionTrajectories() {
    const tracks = new THREE.Group();
    this.scene.sessions.forEach((s, k) => {
      if (s.trajectory && s.trajectory.length >= 6) tracks.add(line(s.trajectory, hex(sessionColor(k))));
    });
    if (!tracks.children.length) return;
    this.sessionLines = tracks;
    this.sessionLines.visible = this.mapColouring === 'session';
    const layer = new THREE.Group();  // switched by its checkbox, the lines inside by the colouring
    layer.add(tracks);
    this.add('session trajectories', onTop(layer, 1));
  }

  // How many sessions' trajectories are drawn now.
  shownSessionTrajectories() {
    const l = this.sessionLines;
    return l && l.visible && this.layers['session trajectories'].visible ? l.children.length : 0;
  }

  // The map's colours as drawn: [r, g, b, how many points or centroids], most frequent first.
  mapColours() {
    const counts = new Map();
    for (let i = 0; i < this.mapColors.length; i += 3) {
      const key = `${this.mapColors[i]},${this.mapColors[i + 1]},${this.mapColors[i + 2]}`;
      counts.set(key, (counts.get(key) || 0) + 1);
    }
    return [...counts].sort((a, b) => b[1] - a[1]).map(([key, n]) => [...key.split(',').map(Number), n]);
  }

  buildSegmentRun() {
    const s = this.scene.segments;
    if (!s) return;
    this.segmentColors = new Uint8Array(s.points.positions.length);
    this.add('segments', discs(s.points.positions, this.segmentColors, 0.08, 1.5));
    this.colourSegmentRun();
  }

  colourSegmentRun() {
    const s = this.scene.segments;
    if (!s) return;
    const n = this.segmentColors.length / 3;
    const camera = (i) => [s.rgb[3 * i], s.rgb[3 * i + 1], s.rgb[3 * i + 2]];
    fillColors(this.segmentColors, n, (i) => {
      if (this.colouring === 'camera') return camera(i);
      if (this.colouring === 'segment') return segmentColor(s.ids[s.points.group[i]]);
      return classColor(this.scene.classes, s.pointClasses[i]);
    });
    this.layers.segments.geometry.attributes.rgb.needsUpdate = true;
  }

  setColouring(mode) {
    this.colouring = mode;
    if (mode !== 'camera') {
      this.mapColouring = mode;
      this.colourMap();
    }
    this.colourSegmentRun();
    this.requestRender();
  }

  buildLocalizations() {
    const loc = this.scene.localization;
    if (!loc) return;
    const records = loc.records;
    const t = loc.trajectory;
    if (t && t.groundTruth) this.add('ground truth', onTop(line(t.groundTruth, 0xd0d0d0), 1));
    const estimate = t && t.estimate.length ? t.estimate
      : Float32Array.from(records.flatMap((r) => r.position));
    if (estimate.length >= 6) this.add('estimate', onTop(line(estimate, 0x4aa3ff), 2));
    this.localizationPositions = Float32Array.from(records.flatMap((r) => r.position));
    const colors = fillColors(new Uint8Array(3 * records.length), records.length,
                              (i) => errorColor(records[i].error_m));
    if (records.length)
      this.add('localizations', onTop(discs(this.localizationPositions, colors, 1.2, 8), 4));
    this.selection = new THREE.Group();
    this.add('matches', this.selection);
    this.robot = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 3, 0xff9f1c,
                                       1.2, 0.8);
    this.robot.visible = false;
    onTop(this.robot, 7);
    this.three.add(this.robot);
  }

  // Shows what localization i matched: a yellow ray from the robot to every matched target
  // segment (magenta), the local segments carried into the map by its pose (cyan) and a white
  // line from each to its target: long white lines are a wrong pose. Nothing for null.
  select(i) {
    this.shownMatches = 0;
    if (!this.selection) return;  // no localization run
    this.selection.clear();
    const records = this.scene.localization.records;
    if (i === null || i < 0 || i >= records.length) return this.requestRender();
    const r = records[i];
    const pairs = new Float32Array(r.matches.flat());
    const rays = Float32Array.from(r.matches.flatMap((m) => [...r.position, ...m.slice(3, 6)]));
    const locals = Float32Array.from(r.matches.flatMap((m) => m.slice(0, 3)));
    const targets = Float32Array.from(r.matches.flatMap((m) => m.slice(3, 6)));
    this.selection.add(onTop(discs(new Float32Array(r.position), new Uint8Array([255, 255, 255]),
                                   2.6, 16), 3));
    if (r.matches.length) {
      const n = r.matches.length;
      const colour = (rgb) => fillColors(new Uint8Array(3 * n), n, () => rgb);
      this.selection.add(onTop(segments(rays, 0xffe14d), 5));
      this.selection.add(onTop(segments(pairs, 0xffffff), 5));
      this.selection.add(onTop(discs(locals, colour([0, 230, 230]), 0.9, 7), 6));
      this.selection.add(onTop(discs(targets, colour([240, 60, 240]), 0.9, 7), 6));
      this.shownMatches = n;
    }
    this.requestRender();
  }

  // The robot at a trajectory row: its estimated pose when there is one, else ground truth.
  showRobot(position, heading) {
    if (!this.robot) return;
    this.robot.visible = position !== null;
    if (position) {
      this.robot.position.set(position[0], position[1], position[2] + 0.5);
      if (heading) this.robot.setDirection(new THREE.Vector3(...heading).normalize());
    }
    this.requestRender();
  }

  buildSlam() {
    const s = this.scene.slam;
    if (!s) return;
    if (s.odometry.length >= 6) this.add('slam odometry', onTop(line(s.odometry, 0xe05050), 1));
    if (s.trajectory.length >= 6) this.add('slam trajectory', onTop(line(s.trajectory, 0x50dc50), 2));
    const links = [];
    for (const l of s.loops)
      for (const f of [l.old_frame, l.frame]) links.push(...s.trajectory.slice(3 * f, 3 * f + 3));
    if (links.length) this.add('loop closures', onTop(segments(new Float32Array(links), 0xffd000), 3));
  }

  // The bounding box of everything drawn but the grid.
  bounds() {
    const box = new THREE.Box3();
    for (const [name, object] of Object.entries(this.layers))
      if (name !== 'grid') box.expandByObject(object);
    if (box.isEmpty()) box.set(new THREE.Vector3(-10, -10, -1), new THREE.Vector3(10, 10, 1));
    return box;
  }

  buildGrid() {
    const box = this.bounds();
    const size = box.getSize(new THREE.Vector3());
    const extent = Math.max(20, Math.ceil(Math.max(size.x, size.y) / 10) * 10 + 20);
    const grid = new THREE.GridHelper(extent, extent / 10, 0x3a3f4b, 0x262a33);
    grid.rotation.x = Math.PI / 2;
    const c = box.getCenter(new THREE.Vector3());
    grid.position.set(Math.round(c.x), Math.round(c.y), box.min.z);
    this.add('grid', grid);
  }

  fitCamera() {
    const box = this.bounds();
    const c = box.getCenter(new THREE.Vector3());
    const r = Math.max(10, box.getSize(new THREE.Vector3()).length() / 2);
    this.controls.target.copy(c);
    this.camera.position.set(c.x - 0.6 * r, c.y - 1.3 * r, c.z + 1.1 * r);
    this.camera.far = 20 * r;
    this.camera.updateProjectionMatrix();
    this.controls.update();
  }

  setVisible(name, visible) {
    if (!this.layers[name]) return;
    this.layers[name].visible = visible;
    this.requestRender();
  }

  resize() {
    const w = this.canvas.clientWidth || window.innerWidth;
    const h = this.canvas.clientHeight || window.innerHeight;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    setViewport(h * this.renderer.getPixelRatio(), FOV);
    this.requestRender();
  }

  requestRender() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => this.render());
  }

  render() {
    this.pending = false;
    this.renderer.render(this.three, this.camera);
    this.frames = (this.frames || 0) + 1;
  }

  // Client (CSS pixel) coordinates of a scene position, null behind the camera.
  screenPosition(p) {
    const v = new THREE.Vector3(p[0], p[1], p[2]).project(this.camera);
    if (v.z > 1) return null;
    const rect = this.canvas.getBoundingClientRect();
    return { x: rect.left + ((v.x + 1) / 2) * rect.width, y: rect.top + ((1 - v.y) / 2) * rect.height };
  }

  // The localization drawn nearest to a click, within `radius` pixels.
  pick(clientX, clientY, radius = 14) {
    const records = this.scene.localization ? this.scene.localization.records : [];
    let best = null;
    let bestD = radius * radius;
    records.forEach((r, i) => {
      const s = this.screenPosition(r.position);
      if (!s) return;
      const d = (s.x - clientX) ** 2 + (s.y - clientY) ** 2;
      if (d <= bestD) [best, bestD] = [i, d];
    });
    return best;
  }

  // Turns the camera about its target for `ms`, rendering every animation frame; the frames
  // per second reached (what "rotates smoothly" means, measured).
  measureRotation(ms) {
    return new Promise((resolve) => {
      const start = performance.now();
      let frames = 0;
      const step = (now) => {
        const a = ((now - start) / ms) * Math.PI * 2;
        const offset = this.camera.position.clone().sub(this.controls.target);
        offset.applyAxisAngle(new THREE.Vector3(0, 0, 1), a - (this.angle || 0));
        this.angle = a;
        this.camera.position.copy(this.controls.target).add(offset);
        this.camera.lookAt(this.controls.target);
        this.renderer.render(this.three, this.camera);
        frames++;
        if (now - start < ms) requestAnimationFrame(step);
        else resolve({ frames, fps: (1000 * frames) / (now - start) });
      };
      this.angle = 0;
      requestAnimationFrame(step);
    });
  }
}
