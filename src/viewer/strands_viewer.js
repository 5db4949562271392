// flexkin strands viewer: plays many strands (hair, fur) from the data embedded in the page, with
// plain WebGL2; nothing is fetched. The data's layout is written by src/viewer/strands_viewer.cc
// (docs/viewer.md, "Many strands"): a JSON element with the facts and each frame's box and body
// pose, and one base64 element per frame holding its 16-bit codes, delta-coded and zlib-compressed.
// At load every frame is decoded once into one Uint16Array, which both renderers read; the WebGL
// renderer uploads it into one GPU buffer the first time it draws, and draws a frame by pointing
// the position attributes at its part of that buffer, so playing uploads nothing. One draw call (gl.LINES, indexed) draws every strand; the shader turns the codes
// into positions and blends two frames for smooth playback.
// Software WebGL (SwiftShader, llvmpipe) spends about a microsecond setting up each line, whatever
// its length, so 320,000 links take about 300 ms a picture there. On such renderers, for many
// links, the page draws the picture itself instead ("software" renderer): every link of every
// strand as a one-pixel line into its own colour and depth buffers, the scalp ray-cast into the
// same buffers, the picture then shown with putImageData on a 2D canvas laid over the WebGL one
// (going through SwiftShader again would cost a texture upload and a read-back per picture).
// The G key switches renderers.
// The page, its controls, keys and view handling are shared with the chain viewer
// (viewer_common.html, .css, .js: flexkinViewerCommon); this is the strands' part.
(function () {
  'use strict';

  const common = flexkinViewerCommon;
  const $ = common.$;
  const api = {
    ready: false, renderer: null, frame: 0, playing: false, error: null,
    // draws: pictures drawn; newPictures: those showing another moment of the motion than the one
    // before; fps: new pictures per second over the last second while playing.
    stats: { ticks: 0, draws: 0, newPictures: 0, drawMs: 0, maxDrawMs: 0, fps: 0 },
  };
  window.flexkinStrandsViewer = api;

  function fail(text) {
    common.showMessage(text);
    api.error = text;
  }

  let meta;
  try {
    meta = JSON.parse($('flexkin-strands').textContent);
  } catch (e) {
    fail('This page holds no strand data. Write it with flexkin (flexkin render of a strand ' +
         'file, or WriteStrandsViewerHtml in C++).');
    return;
  }
  const dim = meta.dim;
  const numFrames = meta.frames.length;
  const numPoints = meta.num_points;
  const numStrands = meta.offsets.length - 1;
  const values = numPoints * dim;  // codes per frame
  // Codes per point in the GPU buffer: always 4 (x, y, z or 0, 0), since 4-component 16-bit
  // attributes are what software Vulkan (SwiftShader under ANGLE) reads without converting the
  // whole buffer on every draw.
  const lanes = 4;
  const frameCodes = numPoints * lanes;
  const options = meta.options;
  Object.assign(api, { dim, numFrames, numPoints, numStrands });

  // ----- Decoding ---------------------------------------------------------------------------------
  function base64Bytes(text) {
    if (Uint8Array.fromBase64) return Uint8Array.fromBase64(text.trim());
    const binary = atob(text.trim());
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
    return bytes;
  }
  async function inflate(bytes) {
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }
  // Frame k's codes into all[k * frameCodes ...], point-major (x, y, z, 0 of point 0, then point 1).
  // Stored component-major as two byte planes (low bytes of every value, then high bytes), each
  // value the difference (mod 2^16) from the same value in the frame before, or, in the first
  // frame, from the value before it in the same component.
  function undelta(raw, all, k) {
    if (raw.length !== 2 * values) throw new Error(`frame ${k}: ${raw.length} bytes, not ${2 * values}`);
    const base = k * frameCodes;
    for (let c = 0; c < dim; ++c) {
      let previous = 0;
      for (let i = 0, j = c * numPoints; i < numPoints; ++i, ++j) {
        const delta = raw[j] | (raw[j + values] << 8);
        const at = base + i * lanes + c;
        const before = k === 0 ? previous : all[at - frameCodes];
        const code = (before + delta) & 0xffff;
        all[at] = code;
        previous = code;
      }
    }
  }
  async function decodeAll() {
    const elements = document.querySelectorAll('script.flexkin-frame');
    if (elements.length !== numFrames) throw new Error(`${elements.length} frames, not ${numFrames}`);
    // One point more at the end: the last point's "next" (the tangent's) must be in the buffer.
    const all = new Uint16Array(numFrames * frameCodes + lanes);
    // Inflating runs off the main thread; the differences need the frames in order.
    const pending = Array.from(elements, (e) => inflate(base64Bytes(e.textContent)));
    for (let k = 0; k < numFrames; ++k) {
      undelta(await pending[k], all, k);
      pending[k] = null;
      $('hint').textContent = `decoding frame ${k + 1} of ${numFrames}`;
    }
    return all;
  }

  // ----- Small matrix helpers (column-major 4x4, as WebGL wants) --------------------------------
  function multiply(a, b) {
    const m = new Float32Array(16);
    for (let c = 0; c < 4; ++c) {
      for (let r = 0; r < 4; ++r) {
        let s = 0;
        for (let k = 0; k < 4; ++k) s += a[k * 4 + r] * b[c * 4 + k];
        m[c * 4 + r] = s;
      }
    }
    return m;
  }
  function lookAt(eye, target, up) {
    const f = normalize(sub(target, eye));
    const s = normalize(cross(f, up));
    const u = cross(s, f);
    return new Float32Array([s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
                             -dot(s, eye), -dot(u, eye), dot(f, eye), 1]);
  }
  function perspective(fovy, aspect, near, far) {
    const t = 1 / Math.tan(fovy / 2);
    return new Float32Array([t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (far + near) / (near - far), -1,
                             0, 0, 2 * far * near / (near - far), 0]);
  }
  function ortho(halfWidth, halfHeight, near, far) {
    return new Float32Array([1 / halfWidth, 0, 0, 0, 0, 1 / halfHeight, 0, 0,
                             0, 0, -2 / (far - near), 0, 0, 0, -(far + near) / (far - near), 1]);
  }
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                           a[0] * b[1] - a[1] * b[0]];
  function normalize(a) {
    const n = Math.hypot(a[0], a[1], a[2]) || 1;
    return [a[0] / n, a[1] / n, a[2] / n];
  }

  // ----- Bounds of the whole motion, for the view ------------------------------------------------
  const boxLo = [Infinity, Infinity, Infinity];
  const boxHi = [-Infinity, -Infinity, -Infinity];
  for (const f of meta.frames) {
    for (let c = 0; c < dim; ++c) {
      boxLo[c] = Math.min(boxLo[c], f.lo[c]);
      boxHi[c] = Math.max(boxHi[c], f.lo[c] + f.ext[c]);
    }
  }
  if (dim === 2) { boxLo[2] = 0; boxHi[2] = 0; }
  const center = [0, 1, 2].map((c) => (boxLo[c] + boxHi[c]) / 2);
  const radius = Math.max(0.5 * Math.hypot(boxHi[0] - boxLo[0], boxHi[1] - boxLo[1],
                                           boxHi[2] - boxLo[2]), 1e-9);

  // ----- WebGL ------------------------------------------------------------------------------------
  const canvas = $('view');
  // No antialiasing: with software rendering it would cost several times the fill.
  const gl = canvas.getContext('webgl2', { antialias: false, alpha: false, depth: true,
                                           preserveDrawingBuffer: false,
                                           powerPreference: 'high-performance' });
  if (!gl) {
    fail('This browser cannot draw WebGL2, which the strands viewer needs.');
    return;
  }
  const background = [0xfb / 255, 0xfb / 255, 0xfd / 255];

  function compile(vertexSource, fragmentSource) {
    const program = gl.createProgram();
    for (const [type, source] of [[gl.VERTEX_SHADER, vertexSource],
                                  [gl.FRAGMENT_SHADER, fragmentSource]]) {
      const shader = gl.createShader(type);
      gl.shaderSource(shader, source);
      gl.compileShader(shader);
      if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
        throw new Error(gl.getShaderInfoLog(shader));
      }
      gl.attachShader(program, shader);
    }
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(program));
    const uniforms = {};
    const count = gl.getProgramParameter(program, gl.ACTIVE_UNIFORMS);
    for (let i = 0; i < count; ++i) {
      const name = gl.getActiveUniform(program, i).name;
      uniforms[name] = gl.getUniformLocation(program, name);
    }
    return { program, uniforms };
  }

  // Positions: the codes of frames a and b (normalized to [0, 1]) times each frame's box, blended.
  // Colour: dark at the root to light at the tip, each strand a little lighter or darker, faded
  // towards the background with depth so that the near strands stand out.
  const strandProgram = compile(`#version 300 es
    layout(location = 0) in vec4 codeA;
    layout(location = 1) in vec4 codeB;
    layout(location = 2) in vec2 along;  // (0 at the root .. 1 at the tip, strand's shade)
    layout(location = 3) in vec4 nextA;  // the codes of the next point in frame a

    uniform vec3 loA, extA, loB, extB;
    uniform float blend;
    uniform mat4 viewMatrix, projection;
    uniform vec2 fog;  // view depths where fading starts and where it is strongest
    uniform vec3 background;
    uniform vec3 light;  // unit vector towards the light
    out vec3 color;
    void main() {
      vec3 p = mix(loA + codeA.xyz * extA, loB + codeB.xyz * extB, blend);
      vec4 v = viewMatrix * vec4(p, 1.0);
      gl_Position = projection * v;
      vec3 root = vec3(0.23, 0.15, 0.09), tip = vec3(0.85, 0.66, 0.40);
      // Hair-like lighting (Kajiya-Kay diffuse): brightest where the strand runs across the light.
      // The tip's "next" point is the next strand's root: its shading only tints the last link.
      vec3 tangent = normalize(loA + nextA.xyz * extA - (loA + codeA.xyz * extA) + vec3(1e-12));
      float across = sqrt(max(0.0, 1.0 - pow(dot(tangent, light), 2.0)));
      vec3 c = mix(root, tip, along.x) * (0.75 + 0.5 * along.y) * (0.35 + 0.8 * across);
      float fade = clamp((-v.z - fog.x) / (fog.y - fog.x), 0.0, 1.0);
      color = mix(c, background, 0.55 * fade);
    }`, `#version 300 es
    precision mediump float;
    in vec3 color;
    out vec4 outColor;
    void main() { outColor = vec4(color, 1.0); }`);

  // The fragment shader of a lit surface (the scalp, the colliders): `color` (GLSL numbers r, g, b)
  // lit from near the viewer, `diffuse` the cosine's expression (one-sided or two-sided).
  const litSurface = (color, diffuse) => `#version 300 es
    precision mediump float;
    in vec3 normal;
    in vec3 toEye;
    out vec4 outColor;
    void main() {
      vec3 n = normalize(normal);
      vec3 l = normalize(normalize(toEye) + vec3(0.3, 0.5, 0.0));
      float diffuse = ${diffuse};
      outColor = vec4(vec3(${color}) * (0.35 + 0.65 * diffuse), 1.0);
    }`;

  // The scalp: a unit sphere scaled to the radii, placed by the body pose, lit from the viewer.
  const scalpProgram = compile(`#version 300 es
    layout(location = 0) in vec3 unit;
    uniform vec3 scalpCenter, radii, translation;
    uniform mat3 rotation;
    uniform mat4 viewMatrix, projection;
    out vec3 normal;
    out vec3 toEye;
    void main() {
      vec4 v = viewMatrix * vec4(rotation * (scalpCenter + radii * unit) + translation, 1.0);
      gl_Position = projection * v;
      normal = mat3(viewMatrix) * rotation * normalize(unit / max(radii, vec3(1e-12)));
      toEye = -v.xyz;
    }`, litSurface('0.80, 0.70, 0.62', 'max(dot(n, l), 0.0)'));

  // Static per-vertex data and the index of every link, built once.
  const strandVao = gl.createVertexArray();
  const positionBuffer = gl.createBuffer();
  let numIndices = 0;
  let codes = null;  // every frame's codes (numFrames * frameCodes + lanes), kept for both renderers
  let uploaded = false;  // whether the GPU holds them (only once the WebGL renderer has drawn)
  function uploadPositions() {
    if (uploaded) return;
    gl.bindBuffer(gl.ARRAY_BUFFER, positionBuffer);
    gl.bufferData(gl.ARRAY_BUFFER, codes, gl.STATIC_DRAW);
    uploaded = true;
  }
  // For the software renderer: each point's colour before lighting and depth (root to tip, the
  // strand's shade), as the shader computes it.
  let baseColor = null;
  function buildStrands() {
    gl.bindVertexArray(strandVao);
    const along = new Uint8Array(2 * numPoints);
    const indices = new Uint32Array(2 * (numPoints - numStrands));
    baseColor = new Float32Array(3 * numPoints);
    let n = 0;
    for (let s = 0; s < numStrands; ++s) {
      const begin = meta.offsets[s], end = meta.offsets[s + 1];
      // A fixed pseudo-random shade per strand (a hash of its index).
      const shade = (Math.imul(s + 1, 2654435761) >>> 24) & 0xff;
      for (let i = begin; i < end; ++i) {
        along[2 * i] = Math.round(255 * (i - begin) / (end - begin - 1));
        along[2 * i + 1] = shade;
        const x = along[2 * i] / 255, k = 0.75 + 0.5 * shade / 255;
        baseColor[3 * i] = (0.23 + (0.85 - 0.23) * x) * k;
        baseColor[3 * i + 1] = (0.15 + (0.66 - 0.15) * x) * k;
        baseColor[3 * i + 2] = (0.09 + (0.40 - 0.09) * x) * k;
        if (i + 1 < end) { indices[n++] = i; indices[n++] = i + 1; }
      }
    }
    numIndices = n;
    const alongBuffer = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, alongBuffer);
    gl.bufferData(gl.ARRAY_BUFFER, along, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(2);
    gl.vertexAttribPointer(2, 2, gl.UNSIGNED_BYTE, true, 0, 0);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(0);
    gl.enableVertexAttribArray(1);
    gl.enableVertexAttribArray(3);
    gl.bindVertexArray(null);
  }

  const scalpVao = gl.createVertexArray();
  let scalpIndices = 0;
  const scalp = meta.scalp && (meta.scalp.shape === 'sphere' || meta.scalp.shape === 'ellipsoid') &&
      dim === 3 ? meta.scalp : null;
  function buildScalp() {
    const rings = 32, sectors = 64;
    const unit = [];
    for (let r = 0; r <= rings; ++r) {
      const theta = Math.PI * r / rings;
      for (let s = 0; s <= sectors; ++s) {
        const phi = 2 * Math.PI * s / sectors;
        unit.push(Math.sin(theta) * Math.cos(phi), Math.sin(theta) * Math.sin(phi), Math.cos(theta));
      }
    }
    const index = [];
    for (let r = 0; r < rings; ++r) {
      for (let s = 0; s < sectors; ++s) {
        const a = r * (sectors + 1) + s, b = a + sectors + 1;
        index.push(a, b, a + 1, a + 1, b, b + 1);
      }
    }
    scalpIndices = index.length;
    gl.bindVertexArray(scalpVao);
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(unit), gl.STATIC_DRAW);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, new Uint16Array(index), gl.STATIC_DRAW);
    gl.bindVertexArray(null);
  }

  // The groom's other colliders (a neck, shoulders, a floor; strands_viewer.cc): triangulated
  // surfaces, the body's placed by each frame's pose, the world's where they are, in the colliders'
  // grey (that of the figures), lit as the scalp is. Shown with the scalp.
  const colliderMeshes = dim === 3 && Array.isArray(meta.colliders) ? meta.colliders : [];
  const colliderGrey = [0.80, 0.80, 0.78];
  const colliderProgram = compile(`#version 300 es
    layout(location = 0) in vec3 position;
    layout(location = 1) in vec3 vertexNormal;
    uniform vec3 translation;
    uniform mat3 rotation;
    uniform mat4 viewMatrix, projection;
    out vec3 normal;
    out vec3 toEye;
    void main() {
      vec4 v = viewMatrix * vec4(rotation * position + translation, 1.0);
      gl_Position = projection * v;
      normal = mat3(viewMatrix) * rotation * vertexNormal;
      toEye = -v.xyz;
    }`, litSurface(colliderGrey.join(', '), 'abs(dot(n, l))'));
  // Per mesh: its VAO and index count, and (for the software renderer) its triangles' normals.
  const colliderParts = [];
  function buildColliders() {
    for (const mesh of colliderMeshes) {
      const v = mesh.vertices, tri = mesh.triangles;
      const normals = new Float32Array(v.length), faces = new Float64Array(tri.length);
      for (let k = 0; k < tri.length; k += 3) {
        const a = 3 * tri[k], b = 3 * tri[k + 1], c = 3 * tri[k + 2];
        const ux = v[b] - v[a], uy = v[b + 1] - v[a + 1], uz = v[b + 2] - v[a + 2];
        const wx = v[c] - v[a], wy = v[c + 1] - v[a + 1], wz = v[c + 2] - v[a + 2];
        const n = [uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx];  // area-weighted
        for (const at of [a, b, c]) for (let j = 0; j < 3; ++j) normals[at + j] += n[j];
        const len = Math.hypot(n[0], n[1], n[2]) || 1;
        for (let j = 0; j < 3; ++j) faces[k + j] = n[j] / len;
      }
      const vao = gl.createVertexArray();
      gl.bindVertexArray(vao);
      gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(v), gl.STATIC_DRAW);
      gl.enableVertexAttribArray(0);
      gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
      gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
      gl.bufferData(gl.ARRAY_BUFFER, normals, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(1);
      gl.vertexAttribPointer(1, 3, gl.FLOAT, false, 0, 0);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, new Uint32Array(tri), gl.STATIC_DRAW);
      gl.bindVertexArray(null);
      colliderParts.push({ vao, count: tri.length, body: mesh.body, moves: mesh.moves,
                           vertices: v, triangles: tri, faces });
    }
  }
  // The body pose between stored frames a and b (rotation row-major, as in the data).
  function bodyPose(a, b, t) {
    const fa = meta.frames[a], fb = meta.frames[b];
    return { R: fa.rotation.map((x, i) => x + t * (fb.rotation[i] - x)),
             T: fa.translation.map((x, i) => x + t * (fb.translation[i] - x)) };
  }
  const identityPose = { R: [1, 0, 0, 0, 1, 0, 0, 0, 1], T: [0, 0, 0] };
  // A part's pose between stored frames a and b: the body's, a keyframed world collider's
  // (each frame's "collider_moves", blended as the body pose is), or none.
  function partPose(part, body, a, b, t) {
    if (part.body) return body;
    if (part.moves === undefined) return identityPose;
    const ma = meta.frames[a].collider_moves[part.moves], mb = meta.frames[b].collider_moves[part.moves];
    const m = ma.map((x, i) => x + t * (mb[i] - x));
    return { R: m.slice(0, 9), T: m.slice(9, 12) };
  }

  // ----- State ------------------------------------------------------------------------------------
  const state = {
    position: 0,  // frames, fractional while blending
    playing: false,
    speed: 1,
    blend: true,
    showScalp: true,
    renderer: 'webgl',  // or 'software'
  };
  const view = { azimuth: 0, elevation: 0, zoom: 1, panX: 0, panY: 0 };
  function resetView() {
    view.azimuth = common.radians(options.azimuth);
    view.elevation = common.radians(options.elevation);
    view.zoom = 1;
    view.panX = 0;
    view.panY = 0;
    requestDraw();
  }

  let width = 1, height = 1;
  function resize() {
    const ratio = window.devicePixelRatio || 1;
    width = Math.max(1, Math.round(canvas.clientWidth * ratio));
    height = Math.max(1, Math.round(canvas.clientHeight * ratio));
    if (canvas.width !== width || canvas.height !== height) {
      canvas.width = width;
      canvas.height = height;
    }
    requestDraw();
  }

  // View and projection matrices, and the depths for the fade.
  const basis = new Float64Array(9);  // the screen's right and up, towards the eye (3D)
  function camera() {
    const aspect = width / height;
    if (dim === 2) {
      const half = 1.1 * radius / view.zoom;
      const hw = aspect >= 1 ? half * aspect : half, hh = aspect >= 1 ? half : half / aspect;
      const eye = [center[0] - view.panX * hw, center[1] - view.panY * hh, 1];
      return { view: lookAt(eye, [eye[0], eye[1], 0], [0, 1, 0]), projection: ortho(hw, hh, 0, 2),
               fog: [1e9, 2e9], eyeDir: [0, 0, 1], near: 0, eye };
    }
    const fovy = 30 * Math.PI / 180;
    const distance = 1.15 * radius / Math.sin(fovy / 2) / Math.min(1, aspect) / view.zoom;
    const b = common.orbitBasis(view.azimuth, view.elevation, basis);
    const dir = [b[6], b[7], b[8]];
    const se = dir[2];
    // Panning moves the target in the screen's plane, in units of the view's half height.
    const right = [b[0], b[1], b[2]], up = [b[3], b[4], b[5]];
    const panScale = distance * Math.tan(fovy / 2);
    const target = [0, 1, 2].map((c) => center[c] - (view.panX * right[c] + view.panY * up[c]) * panScale);
    const eye = [0, 1, 2].map((c) => target[c] + distance * dir[c]);
    const near = Math.max(distance - 2 * radius, distance * 1e-3), far = distance + 2 * radius;
    return { view: lookAt(eye, target, Math.abs(se) > 0.999 ? [0, 1, 0] : [0, 0, 1]),
             projection: perspective(fovy, aspect, near, far),
             fog: [distance - radius, distance + radius], eyeDir: dir, near, eye,
             tanHalf: Math.tan(fovy / 2), aspect };
  }

  // The two stored frames shown and how far between them.
  function shown() {
    const a = Math.min(numFrames - 1, Math.floor(state.position));
    const t = state.blend ? state.position - a : 0;
    const b = t > 0 && a + 1 < numFrames ? a + 1 : a;
    return { a, b, t: b === a ? 0 : t };
  }

  let drawRequested = false, lastShown = '';
  function requestDraw() { drawRequested = true; }

  function draw() {
    const start = performance.now();
    const cam = camera();
    const { a, b, t } = shown();
    if (state.renderer === 'software') drawSoftware(cam, a, b, t);
    else drawWebGL(cam, a, b, t);

    common.countDraw(api.stats, start);
    const key = `${a},${b},${t}`;
    if (key !== lastShown) api.stats.newPictures += 1;
    lastShown = key;
    drawRequested = false;
  }

  // A frame's box, three components also in 2D.
  const box = (f, name) => {
    const v = meta.frames[f][name];
    return dim === 2 ? [v[0], v[1], 0] : v;
  };
  // From above, a little from the viewer's side (in world coordinates; z is up).
  const lightDirection = (cam) => normalize(dim === 3 ? [cam.eyeDir[0] + 0.2, cam.eyeDir[1],
                                                         cam.eyeDir[2] + 1.2] : [0, 0, 1]);

  function drawWebGL(cam, a, b, t) {
    uploadPositions();
    gl.viewport(0, 0, width, height);
    gl.clearColor(background[0], background[1], background[2], 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    if (scalp && state.showScalp) {
      const fa = meta.frames[a], fb = meta.frames[b];
      const r = fa.rotation.map((x, i) => x + t * (fb.rotation[i] - x));
      const p = fa.translation.map((x, i) => x + t * (fb.translation[i] - x));
      const u = scalpProgram.uniforms;
      gl.useProgram(scalpProgram.program);
      // rotation is row-major in the data; a column-major mat3 wants the transpose.
      gl.uniformMatrix3fv(u.rotation, true, r);
      gl.uniform3fv(u.translation, p);
      gl.uniform3fv(u.scalpCenter, scalp.center);
      // Slightly smaller than the scalp, so that the roots on its surface stay visible.
      gl.uniform3fv(u.radii, scalp.radii.map((x) => 0.985 * x));
      gl.uniformMatrix4fv(u.viewMatrix, false, cam.view);
      gl.uniformMatrix4fv(u.projection, false, cam.projection);
      gl.bindVertexArray(scalpVao);
      gl.drawElements(gl.TRIANGLES, scalpIndices, gl.UNSIGNED_SHORT, 0);
    }
    if (colliderParts.length > 0 && state.showScalp) {
      const body = bodyPose(a, b, t);
      const u = colliderProgram.uniforms;
      gl.useProgram(colliderProgram.program);
      gl.uniformMatrix4fv(u.viewMatrix, false, cam.view);
      gl.uniformMatrix4fv(u.projection, false, cam.projection);
      for (const part of colliderParts) {
        const pose = partPose(part, body, a, b, t);
        gl.uniformMatrix3fv(u.rotation, true, pose.R);
        gl.uniform3fv(u.translation, pose.T);
        gl.bindVertexArray(part.vao);
        gl.drawElements(gl.TRIANGLES, part.count, gl.UNSIGNED_INT, 0);
      }
    }
    const u = strandProgram.uniforms;
    gl.useProgram(strandProgram.program);
    gl.uniform3fv(u.loA, box(a, 'lo'));
    gl.uniform3fv(u.extA, box(a, 'ext'));
    gl.uniform3fv(u.loB, box(b, 'lo'));
    gl.uniform3fv(u.extB, box(b, 'ext'));
    gl.uniform1f(u.blend, t);
    gl.uniformMatrix4fv(u.viewMatrix, false, cam.view);
    gl.uniformMatrix4fv(u.projection, false, cam.projection);
    gl.uniform2fv(u.fog, cam.fog);
    gl.uniform3fv(u.background, background);
    gl.uniform3fv(u.light, lightDirection(cam));
    gl.bindVertexArray(strandVao);
    gl.bindBuffer(gl.ARRAY_BUFFER, positionBuffer);
    gl.vertexAttribPointer(0, lanes, gl.UNSIGNED_SHORT, true, 2 * lanes, 2 * a * frameCodes);
    gl.vertexAttribPointer(1, lanes, gl.UNSIGNED_SHORT, true, 2 * lanes, 2 * b * frameCodes);
    gl.vertexAttribPointer(3, lanes, gl.UNSIGNED_SHORT, true, 2 * lanes, 2 * (a * frameCodes + lanes));
    gl.drawElements(gl.LINES, numIndices, gl.UNSIGNED_INT, 0);
    gl.bindVertexArray(null);
  }
  // ----- The software renderer --------------------------------------------------------------------
  // The picture (row 0 at the top), shown with putImageData on a 2D canvas over the WebGL one:
  // colours as RGBA bytes, depths as the view distance along the viewing direction. Links are one-pixel lines stepped along their longer
  // axis, one colour per link (that of its first point, lit and faded as the shader does), depth
  // interpolated along the line and tested as GL's LESS does.
  let pixels32 = null, image = null, depths = null, softContext = null;
  // Colours are never negative here. Packed as a signed 32-bit integer (a small integer to V8,
  // where an unsigned one above 2^31 would be a heap number), stored as the same bits.
  const toByte = (x) => { const v = (x * 255 + 0.5) | 0; return v > 255 ? 255 : v; };
  const pack = (r, g, b) => (-16777216 | (toByte(b) << 16) | (toByte(g) << 8) | toByte(r));
  const backgroundPacked = pack(background[0], background[1], background[2]);
  let offsets32 = null;

  let rowWidth = 1, clipX = 0, clipY = 0;  // the picture's width, and the largest x and y drawn
  // A line from (x0, y0) to (x1, y1) in pixels, depths z0 to z1, colour col; clipped to the
  // picture (Liang-Barsky).
  function line(x0, y0, z0, x1, y1, z1, col) {
    if (x0 >= 0 && x0 < clipX && y0 >= 0 && y0 < clipY && x1 >= 0 && x1 < clipX && y1 >= 0 &&
        y1 < clipY) {
      span(x0, y0, z0, x1 - x0, y1 - y0, z1 - z0, col);
    } else {
      clipped(x0, y0, z0, x1, y1, z1, col);
    }
  }
  // Pixels from (x0, y0) on, n steps along (dx, dy), all inside the picture.
  function span(x0, y0, z0, dx, dy, dz, col) {
    const ax = dx < 0 ? -dx : dx, ay = dy < 0 ? -dy : dy;
    const n = ax > ay ? ax : ay;
    const steps = n < 1 ? 1 : (n + 0.5) | 0;
    const inv = 1 / steps;
    const ix = dx * inv, iy = dy * inv, iz = dz * inv;
    let x = x0, y = y0, z = z0;
    for (let k = 0; k < steps; ++k) {
      const at = (y | 0) * rowWidth + (x | 0);
      if (z < depths[at]) { depths[at] = z; pixels32[at] = col; }
      x += ix; y += iy; z += iz;
    }
  }
  function clipped(x0, y0, z0, x1, y1, z1, col) {
    let dx = x1 - x0, dy = y1 - y0, dz = z1 - z0;
    {
      let t0 = 0, t1 = 1;
      const p = [-dx, dx, -dy, dy], q = [x0, clipX - x0, y0, clipY - y0];
      for (let k = 0; k < 4; ++k) {
        if (p[k] === 0) {
          if (q[k] < 0) return;
        } else {
          const r = q[k] / p[k];
          if (p[k] < 0) { if (r > t1) return; if (r > t0) t0 = r; } else { if (r < t0) return; if (r < t1) t1 = r; }
        }
      }
      const nx0 = x0 + t0 * dx, ny0 = y0 + t0 * dy, nz0 = z0 + t0 * dz;
      x1 = x0 + t1 * dx; y1 = y0 + t1 * dy; z1 = z0 + t1 * dz;
      x0 = Math.min(Math.max(nx0, 0), clipX); y0 = Math.min(Math.max(ny0, 0), clipY); z0 = nz0;
      x1 = Math.min(Math.max(x1, 0), clipX); y1 = Math.min(Math.max(y1, 0), clipY);
      span(x0, y0, z0, x1 - x0, y1 - y0, z1 - z0, col);
    }
  }

  function drawSoftware(cam, a, b, t) {
    const W = width, H = height;
    if (!image || image.width !== W || image.height !== H) {
      const soft = $('soft-view');
      soft.width = W;
      soft.height = H;
      softContext = soft.getContext('2d', { alpha: false });
      image = softContext.createImageData(W, H);
      pixels32 = new Uint32Array(image.data.buffer);
      depths = new Float32Array(W * H);
    }
    if (!offsets32) offsets32 = Int32Array.from(meta.offsets);
    pixels32.fill(backgroundPacked);
    depths.fill(Infinity);
    if (scalp && state.showScalp) castScalp(cam, a, b, t);
    if (colliderParts.length > 0 && state.showScalp) fillColliders(cam, a, b, t);

    const M = multiply(cam.projection, cam.view);
    const m0 = M[0], m4 = M[4], m8 = M[8], m12 = M[12];
    const m1 = M[1], m5 = M[5], m9 = M[9], m13 = M[13];
    const m3 = M[3], m7 = M[7], m11 = M[11], m15 = M[15];
    // World position = origin + codes of frame a * scaleA + codes of frame b * scaleB.
    const u = 1 - t, la = box(a, 'lo'), ea = box(a, 'ext'), lb = box(b, 'lo'), eb = box(b, 'ext');
    const ox = u * la[0] + t * lb[0], oy = u * la[1] + t * lb[1], oz = u * la[2] + t * lb[2];
    const sax = u * ea[0] / 65535, say = u * ea[1] / 65535, saz = u * ea[2] / 65535;
    const sbx = t * eb[0] / 65535, sby = t * eb[1] / 65535, sbz = t * eb[2] / 65535;
    const fa = a * frameCodes, fb = b * frameCodes;
    const l = lightDirection(cam), lx = l[0], ly = l[1], lz = l[2];
    const fog0 = cam.fog[0], fogScale = 1 / (cam.fog[1] - cam.fog[0]);
    const bgR = background[0], bgG = background[1], bgB = background[2];
    const halfW = W / 2, halfH = H / 2, nearW = Math.max(cam.near, 1e-12);
    const c = codes, base = baseColor, offs = offsets32;
    rowWidth = W;
    clipX = W - 1e-3;
    clipY = H - 1e-3;

    for (let s = 0; s < numStrands; ++s) {
      const begin = offs[s], end = offs[s + 1];
      // The previous point: world position, clip w, pixel position.
      let pX = 0, pY = 0, pZ = 0, pcx = 0, pcy = 0, pw = 0, psx = 0, psy = 0;
      for (let i = begin; i < end; ++i) {
        const ia = fa + i * lanes, ib = fb + i * lanes;
        const X = ox + c[ia] * sax + c[ib] * sbx;
        const Y = oy + c[ia + 1] * say + c[ib + 1] * sby;
        const Z = oz + c[ia + 2] * saz + c[ib + 2] * sbz;
        const cx = m0 * X + m4 * Y + m8 * Z + m12;
        const cy = m1 * X + m5 * Y + m9 * Z + m13;
        const cw = m3 * X + m7 * Y + m11 * Z + m15;
        let sx = 0, sy = 0;
        if (cw > nearW) {
          const inv = 1 / cw;
          sx = (cx * inv + 1) * halfW;
          sy = (1 - cy * inv) * halfH;
        }
        if (i > begin && (cw > nearW || pw > nearW)) {
          // The link from the previous point, coloured as the shader colours its first point.
          const tx = X - pX, ty = Y - pY, tz = Z - pZ;
          const tt = tx * tx + ty * ty + tz * tz, tl = tx * lx + ty * ly + tz * lz;
          const cos2 = tt > 0 ? tl * tl / tt : 0;
          const across = cos2 < 1 ? Math.sqrt(1 - cos2) : 0;
          const light = 0.35 + 0.8 * across;
          let fade = (pw - fog0) * fogScale;
          fade = 0.55 * (fade < 0 ? 0 : fade > 1 ? 1 : fade);
          const j = 3 * (i - 1);
          const r = base[j] * light, g = base[j + 1] * light, bl = base[j + 2] * light;
          const col = pack(r + (bgR - r) * fade, g + (bgG - g) * fade, bl + (bgB - bl) * fade);
          if (cw > nearW && pw > nearW) {
            line(psx, psy, pw, sx, sy, cw, col);
          } else {
            // One end behind the near plane: cut the link there (in clip coordinates).
            const k = (pw - nearW) / (pw - cw);
            const qx = pcx + k * (cx - pcx), qy = pcy + k * (cy - pcy);
            const qsx = (qx / nearW + 1) * halfW, qsy = (1 - qy / nearW) * halfH;
            if (pw > nearW) line(psx, psy, pw, qsx, qsy, nearW, col);
            else line(qsx, qsy, nearW, sx, sy, cw, col);
          }
        }
        pX = X; pY = Y; pZ = Z; pcx = cx; pcy = cy; pw = cw; psx = sx; psy = sy;
      }
    }
    softContext.putImageData(image, 0, 0);
  }

  // The scalp into the software picture: each pixel's ray against the ellipsoid placed by the body
  // pose, lit as the WebGL renderer's shader lights it.
  function castScalp(cam, a, b, t) {
    const W = width, H = height;
    const fa = meta.frames[a], fb = meta.frames[b];
    const R = fa.rotation.map((x, i) => x + t * (fb.rotation[i] - x));  // row-major
    const T = fa.translation.map((x, i) => x + t * (fb.translation[i] - x));
    const C = scalp.center, r = scalp.radii.map((x) => Math.max(0.985 * x, 1e-12));
    const V = cam.view;
    const sv = [V[0], V[4], V[8]], uv = [V[1], V[5], V[9]], fv = [-V[2], -V[6], -V[10]];
    const toLocal = (w) => [0, 1, 2].map((k) => (R[k] * w[0] + R[3 + k] * w[1] + R[6 + k] * w[2]) / r[k]);
    const e = cam.eye;
    const o = [0, 1, 2].map((k) => (R[k] * (e[0] - T[0]) + R[3 + k] * (e[1] - T[1]) +
                                    R[6 + k] * (e[2] - T[2]) - C[k]) / r[k]);
    const ax = cam.aspect * cam.tanHalf, ay = cam.tanHalf;
    const D0 = toLocal(fv), DX = toLocal(sv.map((x) => x * ax)), DY = toLocal(uv.map((x) => x * ay));
    // Pixels the scalp can cover: its box's corners projected (all the picture if one is behind).
    let x0 = 0, x1 = W, y0 = 0, y1 = H;
    const M = multiply(cam.projection, cam.view);
    let behind = false, minX = Infinity, maxX = -Infinity, minY = Infinity, maxY = -Infinity;
    for (let k = 0; k < 8; ++k) {
      const lc = [0, 1, 2].map((j) => C[j] + ((k >> j) & 1 ? r[j] : -r[j]));
      const w = [0, 1, 2].map((j) => R[3 * j] * lc[0] + R[3 * j + 1] * lc[1] + R[3 * j + 2] * lc[2] + T[j]);
      const cw = M[3] * w[0] + M[7] * w[1] + M[11] * w[2] + M[15];
      if (cw <= cam.near) { behind = true; break; }
      const sx = ((M[0] * w[0] + M[4] * w[1] + M[8] * w[2] + M[12]) / cw + 1) * W / 2;
      const sy = (1 - (M[1] * w[0] + M[5] * w[1] + M[9] * w[2] + M[13]) / cw) * H / 2;
      minX = Math.min(minX, sx); maxX = Math.max(maxX, sx);
      minY = Math.min(minY, sy); maxY = Math.max(maxY, sy);
    }
    if (!behind) {
      x0 = Math.max(0, Math.floor(minX)); x1 = Math.min(W, Math.ceil(maxX) + 1);
      y0 = Math.max(0, Math.floor(minY)); y1 = Math.min(H, Math.ceil(maxY) + 1);
    }
    const oo = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - 1;
    const near = cam.near;
    // View-space light offset of the scalp shader.
    for (let py = y0; py < y1; ++py) {
      const yn = 1 - (py + 0.5) / H * 2;
      for (let px = x0; px < x1; ++px) {
        const xn = (px + 0.5) / W * 2 - 1;
        const dx = D0[0] + xn * DX[0] + yn * DY[0];
        const dy = D0[1] + xn * DX[1] + yn * DY[1];
        const dz = D0[2] + xn * DX[2] + yn * DY[2];
        const A = dx * dx + dy * dy + dz * dz, B = o[0] * dx + o[1] * dy + o[2] * dz;
        const disc = B * B - A * oo;
        if (disc < 0) continue;
        const th = (-B - Math.sqrt(disc)) / A;
        if (th <= near) continue;
        const at = py * W + px;
        if (!(th < depths[at])) continue;
        depths[at] = th;
        // Normal: the unit-sphere point divided by the radii, rotated to world, then to view.
        const nx = (o[0] + th * dx) / r[0], ny = (o[1] + th * dy) / r[1], nz = (o[2] + th * dz) / r[2];
        const wx = R[0] * nx + R[1] * ny + R[2] * nz;
        const wy = R[3] * nx + R[4] * ny + R[5] * nz;
        const wz = R[6] * nx + R[7] * ny + R[8] * nz;
        const vx = sv[0] * wx + sv[1] * wy + sv[2] * wz;
        const vy = uv[0] * wx + uv[1] * wy + uv[2] * wz;
        const vz = -(fv[0] * wx + fv[1] * wy + fv[2] * wz);
        const vn = Math.sqrt(vx * vx + vy * vy + vz * vz) || 1;
        // Towards the eye in view space, normalized, plus (0.3, 0.5, 0), normalized.
        const ex = -xn * ax, ey = -yn * ay, en = Math.sqrt(ex * ex + ey * ey + 1);
        const hx = ex / en + 0.3, hy = ey / en + 0.5, hz = 1 / en;
        const hn = Math.sqrt(hx * hx + hy * hy + hz * hz);
        const diffuse = Math.max(0, (vx * hx + vy * hy + vz * hz) / (vn * hn));
        const k = 0.35 + 0.65 * diffuse;
        pixels32[at] = pack(0.80 * k, 0.70 * k, 0.62 * k);
      }
    }
  }

  // The colliders into the software picture: each triangle placed (by the body pose for the
  // body's), projected and filled where it is nearer than what is there (depth: the view distance,
  // interpolated in 1/w as the GPU does), shaded flat by its normal with the shader's light.
  // Triangles reaching behind the near plane are left out.
  function fillColliders(cam, a, b, t) {
    const W = width, H = height;
    const M = multiply(cam.projection, cam.view), V = cam.view;
    const body = bodyPose(a, b, t);
    const near = cam.near;
    const sx = new Float64Array(3), sy = new Float64Array(3), iw = new Float64Array(3);
    const wp = [new Float64Array(3), new Float64Array(3), new Float64Array(3)];
    for (const part of colliderParts) {
      const { R, T } = partPose(part, body, a, b, t);
      const v = part.vertices, tri = part.triangles, faces = part.faces;
      for (let k = 0; k < tri.length; k += 3) {
        let behind = false;
        for (let c = 0; c < 3; ++c) {
          const at = 3 * tri[k + c];
          const p = wp[c];
          for (let j = 0; j < 3; ++j) {
            p[j] = R[3 * j] * v[at] + R[3 * j + 1] * v[at + 1] + R[3 * j + 2] * v[at + 2] + T[j];
          }
          const cw = M[3] * p[0] + M[7] * p[1] + M[11] * p[2] + M[15];
          if (cw <= near) { behind = true; break; }
          sx[c] = ((M[0] * p[0] + M[4] * p[1] + M[8] * p[2] + M[12]) / cw + 1) * W / 2;
          sy[c] = (1 - (M[1] * p[0] + M[5] * p[1] + M[9] * p[2] + M[13]) / cw) * H / 2;
          iw[c] = 1 / cw;
        }
        if (behind) continue;
        const area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
        if (area === 0) continue;
        // Flat shade: the face's normal and the way to the eye from its centre, in view space.
        const fn = [0, 1, 2].map((j) => R[3 * j] * faces[k] + R[3 * j + 1] * faces[k + 1] +
                                        R[3 * j + 2] * faces[k + 2]);
        const n = [0, 1, 2].map((j) => V[j] * fn[0] + V[4 + j] * fn[1] + V[8 + j] * fn[2]);
        const mid = [0, 1, 2].map((j) => (wp[0][j] + wp[1][j] + wp[2][j]) / 3);
        const e = [0, 1, 2].map((j) => -(V[j] * mid[0] + V[4 + j] * mid[1] + V[8 + j] * mid[2] +
                                         V[12 + j]));
        const en = Math.hypot(e[0], e[1], e[2]) || 1;
        const l = normalize([e[0] / en + 0.3, e[1] / en + 0.5, e[2] / en]);
        const nn = Math.hypot(n[0], n[1], n[2]) || 1;
        const shade = 0.35 + 0.65 * Math.abs((n[0] * l[0] + n[1] * l[1] + n[2] * l[2]) / nn);
        const col = pack(colliderGrey[0] * shade, colliderGrey[1] * shade, colliderGrey[2] * shade);
        const x0 = Math.max(0, Math.floor(Math.min(sx[0], sx[1], sx[2])));
        const x1 = Math.min(W - 1, Math.ceil(Math.max(sx[0], sx[1], sx[2])));
        const y0 = Math.max(0, Math.floor(Math.min(sy[0], sy[1], sy[2])));
        const y1 = Math.min(H - 1, Math.ceil(Math.max(sy[0], sy[1], sy[2])));
        const inv = 1 / area;
        for (let py = y0; py <= y1; ++py) {
          const y = py + 0.5;
          for (let px = x0; px <= x1; ++px) {
            const x = px + 0.5;
            const b0 = ((sx[1] - x) * (sy[2] - y) - (sx[2] - x) * (sy[1] - y)) * inv;
            const b1 = ((sx[2] - x) * (sy[0] - y) - (sx[0] - x) * (sy[2] - y)) * inv;
            const b2 = 1 - b0 - b1;
            if (b0 < 0 || b1 < 0 || b2 < 0) continue;
            const depth = 1 / (b0 * iw[0] + b1 * iw[1] + b2 * iw[2]);
            const at = py * W + px;
            if (depth < depths[at]) { depths[at] = depth; pixels32[at] = col; }
          }
        }
      }
    }
  }

  // The renderer: software where WebGL itself runs in software and the links are many.
  const debugInfo = gl.getExtension('WEBGL_debug_renderer_info');
  const rendererName = String(gl.getParameter(debugInfo ? debugInfo.UNMASKED_RENDERER_WEBGL
                                                        : gl.RENDERER) || '');
  const softwareGl = /swiftshader|llvmpipe|softpipe|software/i.test(rendererName);
  const softwareFrom = 20000;  // links
  function setRenderer(name) {
    state.renderer = name;
    api.renderer = name;
    $('soft-view').hidden = name !== 'software';
    requestDraw();
    showPerf();
  }

  // ----- Playback -----------------------------------------------------------------------------------
  const framesPerSecond = () => (numFrames - 1) / options.playback_seconds * state.speed;
  let lastTick = null;
  const recent = [];  // times of recent new pictures, for stats.fps
  function tick(now) {
    api.stats.ticks += 1;
    if (state.playing && lastTick !== null && numFrames > 1) {
      let p = state.position + (now - lastTick) / 1000 * framesPerSecond();
      if (p >= numFrames - 1) {
        if (options.loop) {
          p = p % (numFrames - 1);
        } else {
          p = numFrames - 1;
          setPlaying(false);
        }
      }
      setPosition(p, false);
    }
    lastTick = now;
    if (drawRequested) {
      const before = api.stats.newPictures;
      draw();
      if (api.stats.newPictures !== before) recent.push(now);
    }
    while (recent.length && recent[0] < now - 1000) recent.shift();
    if (state.playing) api.stats.fps = recent.length;
    if (api.stats.ticks % 15 === 0) showPerf();
    requestAnimationFrame(tick);
  }

  function setPosition(p, snap = true) {
    p = Math.max(0, Math.min(numFrames - 1, p));
    if (snap || !state.blend) p = Math.floor(p + (snap ? 0.5 : 0));
    if (p === state.position) return;
    const before = Math.floor(state.position);
    state.position = p;
    api.frame = Math.min(numFrames - 1, Math.floor(p));
    requestDraw();
    if (api.frame !== before || snap) showFrame();
  }
  const setFrame = (k) => setPosition(k, true);

  function setPlaying(on) {
    if (on && state.position >= numFrames - 1 && !options.loop) setFrame(0);
    state.playing = on;
    api.playing = on;
    common.showPlaying(on);
    if (!on) {
      api.stats.fps = 0;
      recent.length = 0;
    }
  }
  function setSpeed(x) {
    state.speed = x;
    common.showSpeed(x);
  }

  // ----- Panel --------------------------------------------------------------------------------------
  const fill = common.fillFacts;
  const number = (x, digits = 4) => (Number.isFinite(x) ? Number(x.toPrecision(digits)).toString() : String(x));
  function showFacts() {
    const links = numPoints - numStrands;
    const report = meta.report || {};
    const strands = numStrands === meta.file_strands ? String(numStrands)
                                                       : `${numStrands} of ${meta.file_strands}`;
    fill('facts', [
      ['strands', strands],
      ['links', numStrands ? `${links} (${number(links / numStrands, 3)} per strand)` : '0'],
      ['frames', numFrames === meta.file_frames ? String(numFrames)
                                                 : `${numFrames} of ${meta.file_frames}`],
      ['dimensions', `${dim}D`],
      ['method', meta.method],
      ['file fps', number(meta.fps)],
      ['substeps', String(meta.substeps)],
      ['body', meta.scalp && meta.scalp.shape ? meta.scalp.shape : 'none'],
      ['max length error', report.max_length_error !== undefined ? number(report.max_length_error, 3) : '?'],
      ['engine', report.engine ? `${report.engine}, ${report.threads} thread${report.threads === 1 ? '' : 's'}` : '?'],
      ['stepping time', report.seconds !== undefined ? `${number(report.seconds, 3)} s` : '?'],
      ['page data', `${number(meta.data_bytes / 1e6, 3)} MB (${number(meta.data_bytes / numFrames / 1e3, 3)} kB per frame)`],
      ['precision', `${number(meta.precision, 2)} (largest quantization error)`],
    ]);
  }
  function showFrame() {
    const f = meta.frames[api.frame];
    $('timeline').value = String(api.frame);
    $('counter').textContent = `frame ${api.frame + 1} / ${numFrames}` +
        ` \u00b7 step ${f.frame} \u00b7 t = ${f.time.toFixed(3)} s`;
    fill('now', [['step', String(f.frame)], ['time', `${f.time.toFixed(4)} s`],
                 ['body position', f.translation.map((x) => number(x, 3)).join(', ')]]);
  }
  function showPerf() {
    const s = api.stats;
    fill('perf', [['frames per second', state.playing ? String(s.fps) : '(paused)'],
                  ['line segments', String(numIndices / 2)],
                  ['renderer', state.renderer === 'software'
                      ? 'software: every link drawn by the page (G: WebGL lines)'
                      : 'WebGL lines, one draw call (G: software)'],
                  ['WebGL', rendererName || '?'],
                  ['canvas', `${width} \u00d7 ${height}`]]);
  }

  // ----- Input ----------------------------------------------------------------------------------
  function bind() {
    // Moving the timeline pauses.
    common.bindControls({
      numFrames,
      frame: () => api.frame,
      playing: () => state.playing,
      setPlaying,
      setFrame,
      speed: () => state.speed,
      setSpeed,
      resetView,
      scrubPauses: true,
      keys: {
        i: () => $('blend').click(),
        b: () => { if (scalp) $('scalp').click(); },
        g: () => setRenderer(state.renderer === 'software' ? 'webgl' : 'software'),
      },
    });
    $('blend').addEventListener('change', () => {
      state.blend = $('blend').checked;
      if (!state.blend) setPosition(Math.floor(state.position), false);
      requestDraw();
    });
    $('scalp-control').hidden = !scalp && colliderParts.length === 0;
    $('scalp').addEventListener('change', () => { state.showScalp = $('scalp').checked; requestDraw(); });
    common.bindView(canvas, dim, view, {
      // In units of the view's half height.
      pan(dx, dy) {
        const h = canvas.clientHeight || 1;
        view.panX += 2 * dx / h;
        view.panY -= 2 * dy / h;
      },
      zoom(e) {
        view.zoom = Math.max(0.05, Math.min(200, view.zoom * Math.exp(-e.deltaY * 0.0015)));
      },
      moved: requestDraw,
      resize,
    });
  }

  // ----- For tests: the picture now, and a decoded point ------------------------------------------
  api.pixels = () => {
    draw();
    let d;
    if (state.renderer === 'software') {
      d = image.data;
    } else {
      d = new Uint8Array(width * height * 4);
      gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, d);
    }
    let hash = 2166136261, drawn = 0, grey = 0;
    const colors = new Set();
    for (let i = 0; i < d.length; i += 4) {
      const v = (d[i] << 16) | (d[i + 1] << 8) | d[i + 2];
      hash = Math.imul(hash ^ v, 16777619) >>> 0;
      if (v !== 0xfbfbfd) drawn += 1;
      if (colors.size < 64) colors.add(v);
      // The colliders' grey, lit: red and green equal, blue a little below (not the warm scalp,
      // the coloured strands or the bluish background).
      const rb = d[i] - d[i + 2];
      if (Math.abs(d[i] - d[i + 1]) <= 2 && rb >= 0 && rb <= 6 && d[i] < 240) grey += 1;
    }
    return { hash, drawnFraction: drawn / (d.length / 4), colors: colors.size,
             colliderFraction: grey / (d.length / 4) };
  };
  // Point i (over the embedded strands) of stored frame k, as both renderers read it.
  api.point = (k, i) => {
    const f = meta.frames[k];
    const at = k * frameCodes + i * lanes;
    return f.lo.map((lo, c) => lo + codes[at + c] / 65535 * f.ext[c]);
  };
  api.setRenderer = (name) => setRenderer(name);
  api.setFrame = (k) => { setPlaying(false); setFrame(k); };

  // ----- Start ----------------------------------------------------------------------------------
  $('title').textContent = meta.title;
  document.title = meta.title;
  $('subtitle').textContent = meta.description || '';
  $('hint').textContent = 'decoding';
  decodeAll().then((all) => {
    codes = all;
    buildStrands();
    if (scalp) buildScalp();
    buildColliders();
    setSpeed(1);
    state.blend = $('blend').checked;
    state.renderer = softwareGl && numPoints - numStrands >= softwareFrom ? 'software' : 'webgl';
    setRenderer(state.renderer);
    bind();
    showFacts();
    resetView();
    resize();
    api.frame = 0;
    showFrame();
    common.showHint(dim);
    api.ready = true;
    setPlaying(options.autoplay);
    requestAnimationFrame(tick);
  }).catch((e) => fail(`The page's strand data cannot be decoded: ${e.message}`));
})();
