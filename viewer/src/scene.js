// The scene `semsegmap view` embeds (cpp/semsegmap/viz/scene_export.h), decoded into typed
// arrays: positions relative to scene.origin, points rebuilt from their 16-bit offsets.

const SCENE_FORMAT = 'semsegmap-scene';
const SCENE_VERSION = 2;

function bytesOf(b64) {
  if (typeof Uint8Array.fromBase64 === 'function') return Uint8Array.fromBase64(b64);
  const text = atob(b64);
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i);
  return bytes;
}

// A typed array of `Type` over the bytes of a base64 string (fresh, so always aligned).
function decode(b64, Type) {
  if (b64 === null || b64 === undefined) return null;
  const bytes = bytesOf(b64);
  return new Type(bytes.buffer, bytes.byteOffset, bytes.byteLength / Type.BYTES_PER_ELEMENT);
}

// Absolute (scene-relative) positions of points stored per group as offsets from its centroid.
function pointGroups(json, centroids) {
  const counts = decode(json.counts, Uint32Array);
  const offsets = decode(json.offsets, Int16Array);
  const positions = new Float32Array(offsets.length);
  const group = new Uint32Array(offsets.length / 3);
  let p = 0;
  for (let g = 0; g < counts.length; g++) {
    for (let k = 0; k < counts[g]; k++, p++) {
      for (let c = 0; c < 3; c++)
        positions[3 * p + c] = centroids[3 * g + c] + offsets[3 * p + c] * json.scale;
      group[p] = g;
    }
  }
  return { counts, positions, group };
}

function decodeMap(map) {
  const centroids = decode(map.centroids, Float32Array);
  return {
    name: map.name,
    descriptor: map.descriptor,
    count: map.segments,
    centroids,
    classes: decode(map.classes, Uint16Array),
    sizes: decode(map.sizes, Uint32Array),
    sessions: decode(map.sessions, Uint16Array),  // null: the map of one run, all session 0
    points: map.points ? pointGroups(map.points, centroids) : null,
  };
}

function decodeLocalization(loc) {
  const t = loc.trajectory;
  return {
    ...loc,
    trajectory: t && {
      frames: t.frames,
      groundTruth: decode(t.ground_truth, Float32Array),
      estimate: decode(t.estimate, Float32Array),
      estimateFirstRow: t.estimate_first_row,
    },
  };
}

function decodeSegments(seg) {
  const centroids = decode(seg.centroids, Float32Array);
  return {
    ...seg,
    centroids,
    points: pointGroups(seg.points, centroids),
    pointClasses: decode(seg.point_classes, Uint16Array),
    rgb: decode(seg.rgb, Uint8Array),
  };
}

// Throws an Error saying what is wrong with a scene this page cannot show.
export function decodeScene(json) {
  if (json.format !== SCENE_FORMAT) throw new Error('not a semsegmap scene');
  if (json.version !== SCENE_VERSION)
    throw new Error(`scene version ${json.version}, this page reads ${SCENE_VERSION}: ` +
                    'write it again with the same semsegmap');
  return {
    title: json.title,
    colouring: json.colouring,
    origin: json.origin,
    classes: new Map(json.classes.map((c) => [c.id, c])),
    map: decodeMap(json.map),
    sessions: json.sessions.map((s) => ({ ...s, trajectory: decode(s.trajectory, Float32Array) })),
    localization: json.localization && decodeLocalization(json.localization),
    slam: json.slam && {
      ...json.slam,
      trajectory: decode(json.slam.trajectory, Float32Array),
      odometry: decode(json.slam.odometry, Float32Array),
    },
    segments: json.segments && decodeSegments(json.segments),
  };
}
