// Colours: classes from the class table (unknown excepted), segments by a hash of their index, sessions from a
// fixed qualitative palette, localizations by their error (the bird's-eye pictures' scale: green within 0.5 m, red
// beyond 5 m).

// Class unknown (id 0: what no camera saw, and all of a LiDAR-only map) is black in the class
// table, which the overlays draw over camera pictures; on this page's near-black background it
// would vanish, so here it is a light neutral grey.
export const UNKNOWN_CLASS = 0;
export const UNKNOWN_COLOR = [200, 200, 200];

export function classColor(classes, id) {
  if (id === UNKNOWN_CLASS) return UNKNOWN_COLOR;
  const c = classes.get(id);
  return c ? c.color : [128, 128, 128];
}

// Distinct neighbours: hues a golden angle apart, two lightness levels.
export function segmentColor(index) {
  const h = (index * 0.618033988749895) % 1;
  const l = index % 2 ? 0.55 : 0.7;
  return hslToRgb(h, 0.75, l);
}

// Okabe and Ito's colour-blind safe palette, bright enough on the dark background (its black left out), session 0
// first; sessions beyond it take hues a golden angle apart.
export const SESSION_COLORS = [
  [86, 180, 233],   // sky blue
  [230, 159, 0],    // orange
  [0, 158, 115],    // bluish green
  [240, 228, 66],   // yellow
  [213, 94, 0],     // vermillion
  [204, 121, 167],  // reddish purple
  [0, 114, 178],    // blue
];

export function sessionColor(index) {
  return index < SESSION_COLORS.length ? SESSION_COLORS[index] : segmentColor(index);
}

function hslToRgb(h, s, l) {
  const f = (n) => {
    const k = (n + h * 12) % 12;
    const a = s * Math.min(l, 1 - l);
    return Math.round(255 * (l - a * Math.max(-1, Math.min(k - 3, 9 - k, 1))));
  };
  return [f(0), f(8), f(4)];
}

export const ERROR_STOPS = [
  [0.0, [40, 200, 80]],
  [0.5, [40, 200, 80]],
  [1.0, [240, 220, 60]],
  [2.0, [250, 140, 40]],
  [5.0, [230, 40, 40]],
];

// Unknown error (no ground truth): a neutral blue.
export function errorColor(errorM) {
  if (errorM === null || errorM === undefined) return [90, 160, 255];
  if (errorM >= ERROR_STOPS[ERROR_STOPS.length - 1][0]) return ERROR_STOPS[ERROR_STOPS.length - 1][1];
  for (let i = 1; i < ERROR_STOPS.length; i++) {
    const [e1, c1] = ERROR_STOPS[i];
    if (errorM > e1) continue;
    const [e0, c0] = ERROR_STOPS[i - 1];
    const w = e1 > e0 ? (errorM - e0) / (e1 - e0) : 0;
    return c0.map((v, k) => Math.round(v + w * (c1[k] - v)));
  }
  return ERROR_STOPS[0][1];
}

export const css = (rgb) => `rgb(${rgb[0]},${rgb[1]},${rgb[2]})`;
