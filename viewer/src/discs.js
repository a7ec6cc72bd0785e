// Points drawn as shaded discs of a size in metres (so that they shrink with distance like the
// objects they stand for) but never below a few pixels: one draw call for any number of them.
import * as THREE from 'three';

const vertexShader = `
attribute vec3 rgb;
#ifdef PER_POINT_SIZE
attribute float size;
#else
uniform float size;
#endif
uniform float pixelsPerMetre;
uniform float minPixels;
varying vec3 vRgb;
void main() {
  vRgb = rgb;
  vec4 mv = modelViewMatrix * vec4(position, 1.0);
  gl_PointSize = max(minPixels, size * pixelsPerMetre / max(-mv.z, 0.01));
  gl_Position = projectionMatrix * mv;
}`;

const fragmentShader = `
varying vec3 vRgb;
void main() {
  vec2 c = gl_PointCoord * 2.0 - 1.0;
  float r2 = dot(c, c);
  if (r2 > 1.0) discard;
  gl_FragColor = vec4(vRgb * (1.0 - 0.3 * r2), 1.0);
}`;

const materials = new Set();

// `sizes`: a Float32Array of diameters in metres (one per point), or one number for all.
export function discs(positions, rgb, sizes, minPixels) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setAttribute('rgb', new THREE.BufferAttribute(rgb, 3, true));
  const perPoint = typeof sizes !== 'number';
  if (perPoint) geometry.setAttribute('size', new THREE.BufferAttribute(sizes, 1));
  const material = new THREE.ShaderMaterial({
    vertexShader,
    fragmentShader,
    defines: perPoint ? { PER_POINT_SIZE: 1 } : {},
    uniforms: {
      size: { value: perPoint ? 1 : sizes },
      pixelsPerMetre: { value: 500 },
      minPixels: { value: minPixels },
    },
  });
  materials.add(material);
  geometry.computeBoundingSphere();
  return new THREE.Points(geometry, material);
}

// After a resize: pixels per metre at one metre's distance.
export function setViewport(heightPx, fovDeg) {
  const value = heightPx / (2 * Math.tan((fovDeg * Math.PI) / 360));
  for (const m of materials) m.uniforms.pixelsPerMetre.value = value;
}

// rgb triples (0-255) of n points from colorOf(i) into a Uint8Array.
export function fillColors(target, n, colorOf) {
  for (let i = 0; i < n; i++) {
    const c = colorOf(i);
    target[3 * i] = c[0];
    target[3 * i + 1] = c[1];
    target[3 * i + 2] = c[2];
  }
  return target;
}
