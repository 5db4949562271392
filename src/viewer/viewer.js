// flexkin viewer: plays a chain's recorded motion from the JSON embedded in the page.
// Plain JavaScript and Canvas 2D; nothing is fetched. The data's layout is written by
// src/viewer/viewer_data.cc. Drawing runs in requestAnimationFrame and allocates no arrays per
// frame: positions sit in one Float64Array, projected points in preallocated typed arrays, and
// the grid and the whole leader path are drawn once per view change into a background layer.
// The page, its controls, keys and view handling are shared with the strands viewer
// (viewer_common.html, .css, .js: flexkinViewerCommon); this is the chain's part.
(function () {
  'use strict';

  const common = flexkinViewerCommon;
  const $ = common.$;

  // ----- Data ----------------------------------------------------------------------------------
  let data;
  try {
    data = JSON.parse($('flexkin-data').textContent);
  } catch (e) {
    common.showMessage('This page holds no result data. Write it with flexkin ' +
                       '(flexkin render, or WriteViewerHtml in C++).');
    return;
  }
  const dim = data.dim;
  const numPoints = data.num_links + 1;
  const numFrames = data.steps.length;
  const frameStride = numPoints * dim;
  // Coordinate k of point i in frame f: pos[f * frameStride + i * dim + k].
  const pos = new Float64Array(data.positions);
  data.positions = null;
  const steps = Float64Array.from(data.steps);
  const options = data.options;
  // A robot trajectory (include/flexkin/viewer.h): point 0 the end effector, the last the fixed base.
  const robot = data.robot || null;
  // A tree result (viewer_data.cc, "tree"): link k joins point linkA[k] (its parent, nearer the
  // root) to point linkB[k]; a chain's link k joins points k and k+1.
  const tree = data.tree || null;
  const numLinks = numPoints - 1;
  const linkA = new Int32Array(numLinks), linkB = new Int32Array(numLinks);
  for (let k = 0; k < numLinks; ++k) {
    linkA[k] = tree ? tree.parents[tree.link_points[k]] : k;
    linkB[k] = tree ? tree.link_points[k] : k + 1;
  }
  // The points whose paths are drawn as the leader's: a tree's driven points, else point 0.
  const leaders = tree ? tree.targets : [0];
  // A tree's pointing goals: the point that looks (its target's point) and the points it looked
  // at, frames 1 to numFrames - 1 (dim numbers a frame).
  const looks = tree && tree.looks ? tree.looks.map((l) => ({
    point: tree.targets[l.target], goals: Float64Array.from(l.goals),
  })) : [];

  // Bounding box of the whole motion, its centre and the radius of its bounding sphere.
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let j = 0; j < pos.length; j += dim) {
    for (let k = 0; k < dim; ++k) {
      if (pos[j + k] < lo[k]) lo[k] = pos[j + k];
      if (pos[j + k] > hi[k]) hi[k] = pos[j + k];
    }
  }
  for (const l of looks) {  // the view holds the points looked at too
    for (let j = 0; j < l.goals.length; j += dim) {
      for (let k = 0; k < dim; ++k) {
        lo[k] = Math.min(lo[k], l.goals[j + k]);
        hi[k] = Math.max(hi[k], l.goals[j + k]);
      }
    }
  }
  if (dim === 2) { lo[2] = 0; hi[2] = 0; }
  // The colliders (viewer_data.cc): each holds the box the view must show and the points whose
  // projected convex hull is drawn.
  const colliders = data.colliders || [];
  for (const c of colliders) {
    for (let k = 0; k < 3; ++k) {
      lo[k] = Math.min(lo[k], c.bounds[k]);
      hi[k] = Math.max(hi[k], c.bounds[3 + k]);
    }
  }
  // The links' capsules (viewer_data.cc, "link_radii": one radius per link, link i from point i
  // to point i+1), or null: the view holds them too.
  const linkRadii = data.link_radii ? Float64Array.from(data.link_radii) : null;
  if (linkRadii) {
    const reach = linkRadii.reduce((a, b) => Math.max(a, b), 0);
    for (let k = 0; k < dim; ++k) {
      lo[k] -= reach;
      hi[k] += reach;
    }
  }
  const totalLength = data.link_lengths.reduce((a, b) => a + b, 0);
  const center = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
  const radius = Math.max(0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]),
                          1e-3 * totalLength, 1e-12);

  // ----- View: 2D pan and zoom, 3D orbit ---------------------------------------------------------
  const canvas = $('view');
  const ctx = canvas.getContext('2d');
  const background = document.createElement('canvas');  // grid and whole leader path
  const bgCtx = background.getContext('2d');
  let width = 1, height = 1, pixelRatio = 1;             // CSS pixels, device pixels per CSS pixel
  const view = {
    scale: 1,              // CSS pixels per length unit
    panX: 0, panY: 0,      // CSS pixels
    azimuth: common.radians(options.azimuth),
    elevation: common.radians(options.elevation),
    perspective: options.perspective,
  };
  // Camera basis for 3D: right, up and towards the viewer, 3 numbers each.
  const basis = new Float64Array(9);
  const cameraDistance = 3 * radius;  // perspective: eye distance from the centre

  function updateBasis() {
    common.orbitBasis(view.azimuth, view.elevation, basis);
  }

  function fitView() {
    const margin = 0.9;
    if (dim === 2) {
      const w = Math.max(hi[0] - lo[0], 1e-3 * totalLength, 1e-12);
      const h = Math.max(hi[1] - lo[1], 1e-3 * totalLength, 1e-12);
      view.scale = margin * Math.min(width / w, height / h);
    } else {
      // The nearest points are enlarged by up to 1.5 in perspective.
      view.scale = margin * Math.min(width, height) / (2 * radius) / (view.perspective ? 1.5 : 1);
    }
    view.panX = 0;
    view.panY = 0;
    state.viewMoved = false;
    updateBasis();
  }

  // project() leaves its result here rather than in a new object: CSS pixels and depth
  // (length units towards the viewer, 0 at the centre; always 0 in 2D).
  let sx = 0, sy = 0, sdepth = 0;
  function project(x, y, z) {
    x -= center[0];
    y -= center[1];
    let a = x, b = y, depth = 0, f = 1;
    if (dim === 3) {
      z -= center[2];
      a = x * basis[0] + y * basis[1] + z * basis[2];
      b = x * basis[3] + y * basis[4] + z * basis[5];
      depth = x * basis[6] + y * basis[7] + z * basis[8];
      if (view.perspective) f = cameraDistance / (cameraDistance - depth);
    }
    sx = width / 2 + view.panX + a * view.scale * f;
    sy = height / 2 + view.panY - b * view.scale * f;
    sdepth = depth;
  }
  function projectPoint(frame, i) {
    const o = frame * frameStride + i * dim;
    project(pos[o], pos[o + 1], dim === 3 ? pos[o + 2] : 0);
  }

  // ----- State -----------------------------------------------------------------------------------
  const state = {
    frame: 0,
    playhead: 0,          // frames, fractional while playing
    playing: false,
    speed: 1,
    showLeader: options.show_leader_path,
    showTrails: options.trail_points.length > 0,
    trails: options.trail_points.length > 0 ? options.trail_points.slice() : [numPoints - 1],
    dirty: true,          // redraw the chain
    backgroundDirty: true,
    viewMoved: false,     // panned, zoomed or orbited since the last fit
  };
  const framesPerSecond = numFrames / options.playback_seconds;  // at 1x
  // For tests and the curious: what has been drawn, and how long drawing took.
  const stats = { ticks: 0, draws: 0, drawMs: 0, maxDrawMs: 0 };

  // ----- Drawing ---------------------------------------------------------------------------------
  const colors = {
    background: '#fbfbfd', grid: '#e6e9ef', gridLabel: '#8a93a5', axis: '#c9ced8',
    leader: '#e08a1e', lead: '#d62f2f', tail: '#1d2330', shadow: 'rgba(60, 70, 90, 0.18)',
    collider: '#d2d2cc', colliderEdge: '#85857f', looked: '#73389e',
  };
  // Capsules by depth in 3D, far light, near darker (one colour in 2D: capsuleShades[15]).
  const capsuleShades = [];
  for (let s = 0; s < 16; ++s) {
    const t = s / 15;
    capsuleShades.push('rgb(' + Math.round(226 - 40 * t) + ',' + Math.round(231 - 38 * t) + ',' +
                       Math.round(240 - 26 * t) + ')');
  }
  const trailColors = ['#2a9d8f', '#8e44ad', '#e76f51', '#1f77b4', '#c2185b', '#6a8d1f'];
  // Chain colour and width by depth in 3D: far links light and thin, near ones dark and thick.
  const shades = [];
  for (let s = 0; s < 16; ++s) {
    const t = s / 15;
    shades.push('rgb(' + Math.round(170 - 140 * t) + ',' + Math.round(185 - 135 * t) + ',' +
                Math.round(215 - 95 * t) + ')');
  }
  const screenX = new Float64Array(numPoints);
  const screenY = new Float64Array(numPoints);
  const pointDepth = new Float64Array(numPoints);
  const shadowX = new Float64Array(numPoints);  // a tree's shadow on the floor grid
  const shadowY = new Float64Array(numPoints);
  const linkDepth = new Float64Array(numLinks);
  const linkOrder = Array.from({ length: numLinks }, (_, i) => i);
  const byDepth = (a, b) => linkDepth[a] - linkDepth[b];

  // A round step (1, 2 or 5 times a power of ten) for about `count` grid lines over `range`.
  function niceStep(range, count) {
    const raw = range / count;
    const p = Math.pow(10, Math.floor(Math.log10(raw)));
    const m = raw / p;
    return p * (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10);
  }

  function formatTick(x, step) {
    const decimals = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
    return (Math.abs(x) < step / 2 ? 0 : x).toFixed(decimals);
  }

  function drawGrid2d(g) {
    // World coordinates of the canvas edges.
    const x0 = center[0] + (0 - width / 2 - view.panX) / view.scale;
    const x1 = center[0] + (width - width / 2 - view.panX) / view.scale;
    const y1 = center[1] + (height / 2 + view.panY) / view.scale;
    const y0 = center[1] + (height / 2 + view.panY - height) / view.scale;
    const step = niceStep(Math.max(x1 - x0, y1 - y0), 10);
    g.lineWidth = 1;
    g.strokeStyle = colors.grid;
    g.fillStyle = colors.gridLabel;
    g.font = '11px system-ui, sans-serif';
    g.beginPath();
    for (let x = Math.ceil(x0 / step) * step; x <= x1; x += step) {
      project(x, 0, 0);
      g.moveTo(Math.round(sx) + 0.5, 0);
      g.lineTo(Math.round(sx) + 0.5, height);
    }
    for (let y = Math.ceil(y0 / step) * step; y <= y1; y += step) {
      project(0, y, 0);
      g.moveTo(0, Math.round(sy) + 0.5);
      g.lineTo(width, Math.round(sy) + 0.5);
    }
    g.stroke();
    // Labels along the top and left edges, none in the corners where they would collide.
    g.textBaseline = 'top';
    for (let x = Math.ceil(x0 / step) * step; x <= x1; x += step) {
      project(x, 0, 0);
      if (sx > 36 && sx < width - 30) g.fillText(formatTick(x, step), sx + 3, 3);
    }
    g.textBaseline = 'bottom';
    for (let y = Math.ceil(y0 / step) * step; y <= y1; y += step) {
      project(0, y, 0);
      if (sy > 30 && sy < height - 24) g.fillText(formatTick(y, step), 3, sy - 2);
    }
  }

  function drawGrid3d(g) {
    // A floor grid under the motion and an axis triad in the corner.
    const step = niceStep(Math.max(hi[0] - lo[0], hi[1] - lo[1], 1e-3 * totalLength), 8);
    const xa = Math.floor(lo[0] / step) * step, xb = Math.ceil(hi[0] / step) * step;
    const ya = Math.floor(lo[1] / step) * step, yb = Math.ceil(hi[1] / step) * step;
    const z = lo[2];
    g.lineWidth = 1;
    g.strokeStyle = colors.grid;
    g.beginPath();
    for (let x = xa; x <= xb + step / 2; x += step) {
      project(x, ya, z); g.moveTo(sx, sy);
      project(x, yb, z); g.lineTo(sx, sy);
    }
    for (let y = ya; y <= yb + step / 2; y += step) {
      project(xa, y, z); g.moveTo(sx, sy);
      project(xb, y, z); g.lineTo(sx, sy);
    }
    g.stroke();
    const ox = 36, oy = height - 36, len = 24;
    const names = ['x', 'y', 'z'];
    const axisColors = ['#d62f2f', '#2e9e44', '#2f5fd6'];
    g.font = '11px system-ui, sans-serif';
    g.textAlign = 'center';
    g.textBaseline = 'middle';
    for (let k = 0; k < 3; ++k) {
      const ex = ox + len * basis[k], ey = oy - len * basis[3 + k];
      g.strokeStyle = axisColors[k];
      g.lineWidth = 2;
      g.beginPath();
      g.moveTo(ox, oy);
      g.lineTo(ex, ey);
      g.stroke();
      g.fillStyle = axisColors[k];
      g.fillText(names[k], ox + 1.45 * len * basis[k], oy - 1.45 * len * basis[3 + k]);
    }
    g.textAlign = 'start';
  }

  function drawBackground() {
    const g = bgCtx;
    // Every device pixel, including a last row or column only partly inside `height` or `width`.
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.fillStyle = colors.background;
    g.fillRect(0, 0, background.width, background.height);
    g.setTransform(pixelRatio, 0, 0, pixelRatio, 0, 0);
    if (dim === 2) drawGrid2d(g); else drawGrid3d(g);
    drawColliders(g, stillColliders, 0);
    if (state.showLeader && numFrames > 1) {
      // The whole leader path, faint and dashed; the part travelled is drawn on top per frame.
      g.strokeStyle = colors.leader;
      g.globalAlpha = 0.45;
      g.lineWidth = 1.25;
      g.setLineDash([5, 4]);
      for (const i of leaders) strokePath(g, i, numFrames - 1);
      g.setLineDash([]);
      g.globalAlpha = 1;
    }
    state.backgroundDirty = false;
  }

  // The convex hull of 2D points (Andrew's monotone chain), in order round it.
  function convexHull(points) {
    points.sort((p, q) => p[0] - q[0] || p[1] - q[1]);
    if (points.length < 3) return points;
    const cross = (o, a, b) => (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    const lower = [], upper = [];
    for (const p of points) {
      while (lower.length >= 2 && cross(lower[lower.length - 2], lower[lower.length - 1], p) <= 0) lower.pop();
      lower.push(p);
    }
    for (let i = points.length - 1; i >= 0; --i) {
      const p = points[i];
      while (upper.length >= 2 && cross(upper[upper.length - 2], upper[upper.length - 1], p) <= 0) upper.pop();
      upper.push(p);
    }
    return lower.slice(0, -1).concat(upper.slice(0, -1));
  }

  // The colliders under everything else, far to near: each the hull of its projected points.
  // The background holds those that stay; keyframed ones ("moves": per frame a rotation, row by
  // row, and a translation that carry their points from frame 0) are drawn with each frame.
  const movingColliders = colliders.filter((c) => c.moves);
  const stillColliders = colliders.filter((c) => !c.moves);
  function drawColliders(g, list, frame) {
    if (list.length === 0) return;
    const shapes = list.map((c) => {
      const projected = [];
      let depth = 0;
      const m = c.moves ? c.moves.slice(12 * frame, 12 * frame + 12) : null;
      for (let j = 0; j < c.points.length; j += dim) {
        let x = c.points[j], y = c.points[j + 1], z = dim === 3 ? c.points[j + 2] : 0;
        if (m) {
          const mx = m[0] * x + m[1] * y + m[2] * z + m[9];
          const my = m[3] * x + m[4] * y + m[5] * z + m[10];
          z = m[6] * x + m[7] * y + m[8] * z + m[11];
          x = mx;
          y = my;
        }
        project(x, y, z);
        projected.push([sx, sy]);
        depth += sdepth;
      }
      const floor = c.shape === 'half_space';
      return {hull: convexHull(projected), depth: floor ? -Infinity : depth / projected.length};
    });
    shapes.sort((a, b) => a.depth - b.depth);
    g.fillStyle = colors.collider;
    g.strokeStyle = colors.colliderEdge;
    g.lineWidth = 1.25;
    g.lineJoin = 'round';
    for (const s of shapes) {
      if (s.hull.length < 3) continue;
      g.beginPath();
      g.moveTo(s.hull[0][0], s.hull[0][1]);
      for (let i = 1; i < s.hull.length; ++i) g.lineTo(s.hull[i][0], s.hull[i][1]);
      g.closePath();
      g.fill();
      g.stroke();
    }
  }

  // Strokes point i's positions from frame 0 to frame `last`.
  function strokePath(g, i, last) {
    g.beginPath();
    for (let f = 0; f <= last; ++f) {
      projectPoint(f, i);
      if (f === 0) g.moveTo(sx, sy); else g.lineTo(sx, sy);
    }
    g.stroke();
  }

  // The pointing goals at frame `frame` (> 0): the points looked at so far, a dashed gaze from the
  // looking point to the point it looks at, and a ring there.
  function drawLooks(g, frame) {
    if (frame === 0) return;
    const at = (l, f, k) => l.goals[(f - 1) * dim + k];
    for (const l of looks) {
      g.strokeStyle = colors.looked;
      g.lineWidth = 1.25;
      g.setLineDash([4, 3]);
      g.beginPath();
      for (let f = 1; f <= frame; ++f) {
        project(at(l, f, 0), at(l, f, 1), dim === 3 ? at(l, f, 2) : 0);
        if (f === 1) g.moveTo(sx, sy); else g.lineTo(sx, sy);
      }
      g.stroke();
      projectPoint(frame, l.point);
      const fromX = sx, fromY = sy;
      project(at(l, frame, 0), at(l, frame, 1), dim === 3 ? at(l, frame, 2) : 0);
      g.beginPath();
      g.moveTo(fromX, fromY);
      g.lineTo(sx, sy);
      g.stroke();
      g.setLineDash([]);
      g.beginPath();
      g.arc(sx, sy, 4, 0, 2 * Math.PI);
      g.stroke();
    }
  }

  // Each link of a radius as its capsule, under the links' lines: a stroke from point to point
  // with round caps, 2 x radius wide, which is the outline of a capsule in 2D and the silhouette
  // of one in the orthographic 3D view. In perspective the radius is scaled as a point at the
  // link's midpoint is (the stroke cannot taper). Far capsules first; screenX, screenY and
  // linkDepth hold the frame's projected points.
  const capsuleOrder = Array.from({ length: numPoints - 1 }, (_, i) => i);
  const capsuleDepth = new Float64Array(numPoints - 1);
  const capsuleByDepth = (a, b) => capsuleDepth[a] - capsuleDepth[b];
  function drawCapsules(g) {
    for (let i = 0; i < numLinks; ++i) {
      capsuleDepth[i] = 0.5 * (pointDepth[linkA[i]] + pointDepth[linkB[i]]);
    }
    if (dim === 3) capsuleOrder.sort(capsuleByDepth);
    for (let j = 0; j < capsuleOrder.length; ++j) {
      const i = capsuleOrder[j];
      const r = linkRadii[i];
      if (!(r > 0)) continue;
      const d = capsuleDepth[i];
      const f = dim === 3 && view.perspective ? cameraDistance / (cameraDistance - d) : 1;
      const t = dim === 3 ? Math.min(1, Math.max(0, (d + radius) / (2 * radius))) : 1;
      g.strokeStyle = capsuleShades[Math.round(15 * t)];
      g.lineWidth = 2 * r * view.scale * f;
      g.beginPath();
      g.moveTo(screenX[linkA[i]], screenY[linkA[i]]);
      g.lineTo(screenX[linkB[i]], screenY[linkB[i]]);
      g.stroke();
    }
  }

  // A fixed point's support: a dark triangle, its apex on the point, standing on a ground line.
  function drawSupport(g, bx, by) {
    g.fillStyle = colors.tail;
    g.beginPath();
    g.moveTo(bx, by);
    g.lineTo(bx + 7, by + 10);
    g.lineTo(bx - 7, by + 10);
    g.closePath();
    g.fill();
    g.strokeStyle = colors.tail;
    g.lineWidth = 1.5;
    g.beginPath();
    g.moveTo(bx - 10, by + 10);
    g.lineTo(bx + 10, by + 10);
    g.stroke();
  }

  // A tree's links: one path of separate segments, parent to child.
  function strokeTreeLinks(g, xOf, yOf) {
    g.beginPath();
    for (let k = 0; k < numLinks; ++k) {
      g.moveTo(xOf(linkA[k]), yOf(linkA[k]));
      g.lineTo(xOf(linkB[k]), yOf(linkB[k]));
    }
    g.stroke();
  }

  function drawChain(g, frame) {
    for (let i = 0; i < numPoints; ++i) {
      projectPoint(frame, i);
      screenX[i] = sx;
      screenY[i] = sy;
      pointDepth[i] = sdepth;
    }
    g.lineCap = 'round';
    g.lineJoin = 'round';
    if (linkRadii) drawCapsules(g);
    if (dim === 2) {
      g.strokeStyle = '#2b4c8c';
      g.lineWidth = 3;
      if (tree) {
        strokeTreeLinks(g, (i) => screenX[i], (i) => screenY[i]);
      } else {
        g.beginPath();
        g.moveTo(screenX[0], screenY[0]);
        for (let i = 1; i < numPoints; ++i) g.lineTo(screenX[i], screenY[i]);
        g.stroke();
      }
    } else {
      // The chain's shadow on the floor grid, straight down: where it is over the floor.
      g.strokeStyle = colors.shadow;
      g.lineWidth = 2;
      if (tree) {
        for (let i = 0; i < numPoints; ++i) {
          const o = frame * frameStride + i * dim;
          project(pos[o], pos[o + 1], lo[2]);
          shadowX[i] = sx;
          shadowY[i] = sy;
        }
        strokeTreeLinks(g, (i) => shadowX[i], (i) => shadowY[i]);
      } else {
        g.beginPath();
        for (let i = 0; i < numPoints; ++i) {
          const o = frame * frameStride + i * dim;
          project(pos[o], pos[o + 1], lo[2]);
          if (i === 0) g.moveTo(sx, sy); else g.lineTo(sx, sy);
        }
        g.stroke();
      }
      // Link k joins points linkA[k] and linkB[k]; far links first so near ones cover them.
      for (let k = 0; k < numLinks; ++k) {
        linkDepth[k] = 0.5 * (pointDepth[linkA[k]] + pointDepth[linkB[k]]);
      }
      linkOrder.sort(byDepth);
      for (let j = 0; j < linkOrder.length; ++j) {
        const i = linkOrder[j];
        const t = Math.min(1, Math.max(0, (linkDepth[i] + radius) / (2 * radius)));
        g.strokeStyle = shades[Math.round(15 * t)];
        g.lineWidth = 1.5 + 2.75 * t;
        g.beginPath();
        g.moveTo(screenX[linkA[i]], screenY[linkA[i]]);
        g.lineTo(screenX[linkB[i]], screenY[linkB[i]]);
        g.stroke();
      }
    }
    // Joints, when links are long enough on screen for them to be told apart.
    const linkPixels = view.scale * totalLength / (numPoints - 1);
    if (linkPixels > 7) {
      g.fillStyle = '#ffffff';
      g.strokeStyle = '#2b4c8c';
      g.lineWidth = 1;
      const r = Math.min(3, linkPixels / 5);
      for (let i = tree ? 0 : 1; i < numPoints - (tree ? 0 : 1); ++i) {
        g.beginPath();
        g.arc(screenX[i], screenY[i], r, 0, 2 * Math.PI);
        g.fill();
        g.stroke();
      }
    }
    if (tree) {
      // The fixed points' supports and the driven points.
      for (const i of tree.fixed) drawSupport(g, screenX[i], screenY[i]);
      g.fillStyle = colors.lead;
      for (const i of leaders) {
        g.beginPath();
        g.arc(screenX[i], screenY[i], 5, 0, 2 * Math.PI);
        g.fill();
      }
      return;
    }
    if (robot) {
      // The fixed base.
      drawSupport(g, screenX[numPoints - 1], screenY[numPoints - 1]);
    } else {
      g.fillStyle = colors.tail;
      g.beginPath();
      g.arc(screenX[numPoints - 1], screenY[numPoints - 1], 3.5, 0, 2 * Math.PI);
      g.fill();
    }
    g.fillStyle = colors.lead;
    g.beginPath();
    g.arc(screenX[0], screenY[0], 5, 0, 2 * Math.PI);
    g.fill();
  }

  function draw() {
    const t0 = performance.now();
    if (state.backgroundDirty) drawBackground();
    const g = ctx;
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.drawImage(background, 0, 0);
    g.setTransform(pixelRatio, 0, 0, pixelRatio, 0, 0);
    drawColliders(g, movingColliders, state.frame);
    g.lineCap = 'round';
    g.lineJoin = 'round';
    if (state.showLeader && state.frame > 0) {
      g.strokeStyle = colors.leader;
      g.lineWidth = 2;
      for (const i of leaders) strokePath(g, i, state.frame);
    }
    if (state.showTrails) {
      g.lineWidth = 1.5;
      for (let j = 0; j < state.trails.length; ++j) {
        g.strokeStyle = trailColors[j % trailColors.length];
        strokePath(g, state.trails[j], state.frame);
      }
    }
    if (state.showLeader) drawLooks(g, state.frame);
    drawChain(g, state.frame);
    state.dirty = false;
    common.countDraw(stats, t0);
  }

  function resize() {
    const rect = canvas.getBoundingClientRect();
    const firstTime = width === 1 && height === 1;
    const oldWidth = width, oldHeight = height;
    width = Math.max(1, rect.width);
    height = Math.max(1, rect.height);
    pixelRatio = window.devicePixelRatio || 1;
    canvas.width = background.width = Math.round(width * pixelRatio);
    canvas.height = background.height = Math.round(height * pixelRatio);
    if (firstTime || !state.viewMoved) {
      fitView();
    } else {
      // Keep the picture's size relative to the smaller side.
      view.scale *= Math.min(width, height) / Math.min(oldWidth, oldHeight);
    }
    state.backgroundDirty = true;
    state.dirty = true;
  }

  // ----- Metrics panel ---------------------------------------------------------------------------
  function fmt(x) {
    if (x === 0) return '0';
    const a = Math.abs(x);
    if (a < 1e-3 || a >= 1e6) return x.toExponential(2);
    return String(Number(x.toPrecision(5)));
  }

  const addFact = common.addFact;

  const metrics = data.metrics;
  const nowFields = {};
  // A robot trajectory's panel: its method, targets and what was reached; the end effector and
  // the base for the leading and trailing ends.
  function buildRobotPanel() {
    $('subtitle').textContent = 'robot, ' + data.method + ', ' + dim + 'D, ' + robot.links +
        ' links, ' + robot.targets + ' targets, ' +
        (robot.unreached > 0 ? robot.unreached + ' not reached' : 'all reached');
    const facts = $('facts');
    if (data.scenario) addFact(facts, 'Scenario', data.scenario);
    addFact(facts, 'Method', data.method);
    addFact(facts, 'Dimension', dim + 'D');
    addFact(facts, 'Links', String(robot.links));
    addFact(facts, 'Targets', String(robot.targets));
    const missed = addFact(facts, 'Not reached', String(robot.unreached));
    if (robot.unreached > 0) missed.style.color = colors.lead;
    addFact(facts, 'End-effector error (max)', fmt(robot.max_ee_error));
    addFact(facts, 'Compute time', fmt(data.seconds) + ' s');
    const now = $('now');
    nowFields.step = addFact(now, 'Target', '');
    nowFields.lead = addFact(now, 'End effector', '');
    nowFields.tail = addFact(now, 'Base', '');
    const leader = $('leader').parentNode;
    leader.title = 'The end effector\'s path (L)';
    leader.lastChild.textContent = ' End-effector path';
    const ends = document.querySelectorAll('#profile + .axis span');
    if (ends.length === 2) {
      ends[0].textContent = 'end effector';
      ends[1].textContent = 'base';
    }
    $('l2plot').previousElementSibling.textContent = 'L2 per target';
  }

  function buildPanel() {
    document.title = data.title + ' \u2013 flexkin viewer';
    $('title').textContent = data.title;
    if (robot) {
      buildRobotPanel();
    } else if (tree) {
      buildTreePanel();
    } else {
      buildChainPanel();
    }
    $('perspective-control').hidden = dim !== 3;
    common.showHint(dim, 'click a point: trail');
  }

  // A tree result's panel: its points, targets and fixed points, what was reached; the first
  // driven point and the root for the leading and trailing ends.
  function buildTreePanel() {
    const count = (n, one, many) => n + ' ' + (n === 1 ? one : many);
    $('subtitle').textContent = 'tree, ' + data.method + ', ' + dim + 'D, ' +
        count(numPoints, 'point', 'points') + ', ' + count(tree.targets.length, 'target', 'targets') +
        (tree.fixed.length > 0 ? ', ' + tree.fixed.length + ' fixed' : '') + ', ' +
        (tree.not_reached > 0 ? tree.not_reached + ' frames not reached' : 'all reached');
    const facts = $('facts');
    if (data.scenario) addFact(facts, 'Scenario', data.scenario);
    addFact(facts, 'Method', data.method);
    addFact(facts, 'Dimension', dim + 'D');
    addFact(facts, 'Points', String(numPoints));
    addFact(facts, 'Links (total length)', numLinks + ' (' + fmt(totalLength) + ')');
    addFact(facts, 'Driven points', tree.targets.join(', '));
    if (tree.fixed.length > 0) addFact(facts, 'Fixed points', tree.fixed.join(', '));
    addFact(facts, 'Frames', String(numFrames));
    const missed = addFact(facts, 'Frames not reached', String(tree.not_reached));
    if (tree.not_reached > 0) missed.style.color = colors.lead;
    addFact(facts, 'Link-length error (max)', fmt(metrics.max_relative_length_error));
    addFact(facts, 'L2 total', fmt(metrics.l2_total));
    const now = $('now');
    nowFields.step = addFact(now, 'Frame', '');
    nowFields.error = addFact(now, 'Link-length error', '');
    nowFields.lead = addFact(now, 'Point ' + leaders[0] + ' (driven)', '');
    nowFields.tail = addFact(now, 'Point ' + tree.parents.indexOf(-1) + ' (root)', '');
    const leader = $('leader').parentNode;
    leader.title = 'The driven points\' paths (L)';
    leader.lastChild.textContent = ' Driven paths';
    const ends = document.querySelectorAll('#profile + .axis span');
    if (ends.length === 2) {
      ends[0].textContent = 'point 0';
      ends[1].textContent = 'point ' + (numPoints - 1);
    }
    $('l2plot').previousElementSibling.textContent = 'L2 per frame';
  }

  function buildChainPanel() {
    $('subtitle').textContent = data.method + ', ' + dim + 'D, ' + data.num_links + ' links, ' +
        data.num_steps + ' leader steps';
    const facts = $('facts');
    if (data.scenario) addFact(facts, 'Scenario', data.scenario);
    addFact(facts, 'Method', data.method);
    addFact(facts, 'Dimension', dim + 'D');
    addFact(facts, 'Links', String(data.num_links));
    addFact(facts, 'Chain length', fmt(totalLength));
    addFact(facts, 'Leader steps', String(data.num_steps));
    addFact(facts, 'Frames recorded', String(numFrames));
    addFact(facts, 'Sub-steps per step', String(data.substeps));
    addFact(facts, 'Link-length error (max)', fmt(metrics.max_relative_length_error));
    addFact(facts, 'L2 total', fmt(metrics.l2_total));
    addFact(facts, 'L2 weighted total', fmt(metrics.l2_weighted_total));
    if (data.accuracy.enabled) {
      addFact(facts, 'Estimated error', fmt(data.accuracy.estimated_error) + ' (tolerance ' +
          fmt(data.accuracy.tolerance) + (data.accuracy.met ? ', met)' : ', NOT met)'));
    }
    if (data.method === 'overall') addFact(facts, 'Failed solves', String(data.overall_failures));
    addFact(facts, 'Compute time', fmt(data.seconds) + ' s');
    const now = $('now');
    nowFields.step = addFact(now, 'Leader step', '');
    nowFields.error = addFact(now, 'Link-length error', '');
    nowFields.lead = addFact(now, 'Leading end', '');
    nowFields.tail = addFact(now, 'Trailing end', '');
  }

  // A sparkline of `values` into `canvas`, kept as an image so the marker can be moved cheaply.
  function makeSpark(sparkCanvas, values) {
    const w = sparkCanvas.clientWidth || 260, h = sparkCanvas.clientHeight || 64;
    const r = window.devicePixelRatio || 1;
    sparkCanvas.width = Math.round(w * r);
    sparkCanvas.height = Math.round(h * r);
    const g = sparkCanvas.getContext('2d');
    const image = document.createElement('canvas');
    image.width = sparkCanvas.width;
    image.height = sparkCanvas.height;
    const ig = image.getContext('2d');
    ig.scale(r, r);
    let max = 0, min = Infinity;
    for (let i = 0; i < values.length; ++i) {
      max = Math.max(max, values[i]);
      min = Math.min(min, values[i]);
    }
    const pad = 4;
    const xOf = (i) => pad + (w - 2 * pad) * (values.length > 1 ? i / (values.length - 1) : 0.5);
    const yOf = (v) => h - pad - (h - 2 * pad - 10) * (max > 0 ? v / max : 0);
    ig.fillStyle = 'rgba(43, 76, 140, 0.12)';
    ig.strokeStyle = '#2b4c8c';
    ig.lineWidth = 1.25;
    ig.beginPath();
    for (let i = 0; i < values.length; ++i) ig.lineTo(xOf(i), yOf(values[i]));
    ig.stroke();
    ig.lineTo(xOf(values.length - 1), h - pad);
    ig.lineTo(xOf(0), h - pad);
    ig.fill();
    ig.fillStyle = '#5b6475';
    ig.font = '10px system-ui, sans-serif';
    ig.textBaseline = 'top';
    ig.fillText('max ' + fmt(max) + ' \u00b7 min ' + fmt(values.length ? min : 0), pad + 2, 1);
    return { g, image, w, h, xOf, yOf, r };
  }

  let profileSpark = null, l2Spark = null;
  function drawSparks() {
    if (!profileSpark) {
      profileSpark = makeSpark($('profile'), metrics.path_length);
      l2Spark = makeSpark($('l2plot'), metrics.l2_per_step);
    }
    // Path-length profile, with the points that have trails marked in their colours.
    let s = profileSpark;
    s.g.setTransform(1, 0, 0, 1, 0, 0);
    s.g.clearRect(0, 0, s.image.width, s.image.height);
    s.g.drawImage(s.image, 0, 0);
    s.g.setTransform(s.r, 0, 0, s.r, 0, 0);
    if (state.showTrails && metrics.path_length.length === numPoints) {
      for (let j = 0; j < state.trails.length; ++j) {
        const i = state.trails[j];
        s.g.fillStyle = trailColors[j % trailColors.length];
        s.g.beginPath();
        s.g.arc(s.xOf(i), s.yOf(metrics.path_length[i]), 3, 0, 2 * Math.PI);
        s.g.fill();
      }
    }
    // L2 per step, with the current step marked.
    s = l2Spark;
    s.g.setTransform(1, 0, 0, 1, 0, 0);
    s.g.clearRect(0, 0, s.image.width, s.image.height);
    s.g.drawImage(s.image, 0, 0);
    s.g.setTransform(s.r, 0, 0, s.r, 0, 0);
    const step = steps[state.frame];
    if (step > 0 && metrics.l2_per_step.length > 0) {
      const x = s.xOf(Math.min(step, metrics.l2_per_step.length) - 1);
      s.g.strokeStyle = colors.lead;
      s.g.lineWidth = 1;
      s.g.beginPath();
      s.g.moveTo(x, 0);
      s.g.lineTo(x, s.h);
      s.g.stroke();
    }
  }

  function pointText(frame, i) {
    const o = frame * frameStride + i * dim;
    let text = '(' + fmt(pos[o]);
    for (let k = 1; k < dim; ++k) text += ', ' + fmt(pos[o + k]);
    return text + ')';
  }

  let shownFrame = -1;
  function updateReadouts() {
    if (shownFrame === state.frame) return;
    shownFrame = state.frame;
    const f = state.frame;
    $('timeline').value = String(f);
    $('counter').textContent = 'frame ' + (f + 1) + ' / ' + numFrames +
        (tree ? '' : ' \u00b7 step ' + steps[f] + ' / ' + data.num_steps);
    nowFields.step.textContent = String(steps[f]);
    if (nowFields.error) nowFields.error.textContent = fmt(data.frame_length_error[f]);
    nowFields.lead.textContent = pointText(f, leaders[0]);
    nowFields.tail.textContent = pointText(f, tree ? tree.parents.indexOf(-1) : numPoints - 1);
    drawSparks();
  }

  function updateLegend() {
    const legend = $('legend');
    legend.textContent = '';
    if (!state.showTrails || state.trails.length === 0) return;
    legend.append('Trails:');
    state.trails.forEach((i, j) => {
      const dot = document.createElement('span');
      dot.className = 'swatch';
      dot.style.background = trailColors[j % trailColors.length];
      legend.append(dot, 'point ' + i);
    });
  }

  // ----- Controls --------------------------------------------------------------------------------
  function setFrame(f) {
    state.frame = Math.max(0, Math.min(numFrames - 1, Math.round(f)));
    state.playhead = state.frame;
    state.dirty = true;
  }

  function setPlaying(playing) {
    state.playing = playing && numFrames > 1;
    if (state.playing && state.frame === numFrames - 1 && !options.loop) setFrame(0);
    state.playhead = state.frame;
    common.showPlaying(state.playing);
  }

  function setSpeed(speed) {
    state.speed = speed;
    common.showSpeed(speed);
  }

  function setTrails(text) {
    const list = [];
    for (const part of text.split(/[\s,;]+/)) {
      if (part === '') continue;
      const i = Number(part);
      if (Number.isInteger(i) && i >= 0 && i < numPoints && !list.includes(i)) list.push(i);
    }
    state.trails = list;
    $('trail-points').value = list.join(', ');
    state.dirty = true;
    shownFrame = -1;
    updateLegend();
  }

  function toggleTrail(i) {
    const list = state.trails.slice();
    const at = list.indexOf(i);
    if (at >= 0) list.splice(at, 1); else list.push(i);
    state.showTrails = true;
    $('trails').checked = true;
    setTrails(list.join(','));
  }

  function resetView() {
    view.azimuth = common.radians(options.azimuth);
    view.elevation = common.radians(options.elevation);
    fitView();
    state.backgroundDirty = true;
    state.dirty = true;
  }

  function bindControls() {
    // Moving the timeline while playing plays on from there.
    common.bindControls({
      numFrames,
      frame: () => state.frame,
      playing: () => state.playing,
      setPlaying,
      setFrame,
      speed: () => state.speed,
      setSpeed,
      resetView,
      scrubPauses: false,
      keys: {
        l: () => $('leader').click(),
        t: () => $('trails').click(),
        p: () => { if (dim === 3) $('perspective').click(); },
      },
    });
    $('leader').checked = state.showLeader;
    $('leader').addEventListener('change', (e) => {
      state.showLeader = e.target.checked;
      state.backgroundDirty = true;
      state.dirty = true;
    });
    $('trails').checked = state.showTrails;
    $('trails').addEventListener('change', (e) => {
      state.showTrails = e.target.checked;
      state.dirty = true;
      shownFrame = -1;
      updateLegend();
    });
    $('trail-points').value = state.trails.join(', ');
    $('trail-points').addEventListener('change', (e) => setTrails(e.target.value));
    $('perspective').checked = view.perspective;
    $('perspective').addEventListener('change', (e) => {
      view.perspective = e.target.checked;
      resetView();
    });
    common.bindView(canvas, dim, view, {
      pan(dx, dy) {
        view.panX += dx;
        view.panY += dy;
      },
      orbited: updateBasis,
      zoom(e) {
        const rect = canvas.getBoundingClientRect();
        const mx = e.clientX - rect.left - width / 2, my = e.clientY - rect.top - height / 2;
        const k = Math.exp(-e.deltaY * (e.deltaMode === 1 ? 0.05 : 0.0015));
        // Zoom about the cursor: the point under it stays put.
        view.scale *= k;
        view.panX = mx - (mx - view.panX) * k;
        view.panY = my - (my - view.panY) * k;
      },
      moved() {
        state.viewMoved = true;
        state.backgroundDirty = true;
        state.dirty = true;
      },
      click: pick,
      resize,
    });
  }

  // A click near a point of the current frame adds or removes its trail.
  function pick(e) {
    const rect = canvas.getBoundingClientRect();
    const x = e.clientX - rect.left, y = e.clientY - rect.top;
    let best = -1, bestDistance = 10;  // CSS pixels
    for (let i = 0; i < numPoints; ++i) {
      projectPoint(state.frame, i);
      const d = Math.hypot(sx - x, sy - y);
      if (d < bestDistance) { best = i; bestDistance = d; }
    }
    if (best >= 0) toggleTrail(best);
  }

  // ----- Main loop -------------------------------------------------------------------------------
  let lastTime = null;
  function tick(now) {
    requestAnimationFrame(tick);
    stats.ticks += 1;
    if (state.playing) {
      const dt = lastTime === null ? 0 : Math.min(0.25, (now - lastTime) / 1000);
      state.playhead += dt * state.speed * framesPerSecond;
      if (state.playhead >= numFrames) {
        if (options.loop) {
          state.playhead %= numFrames;
        } else {
          state.playhead = numFrames - 1;
          setPlaying(false);
        }
      }
      const frame = Math.floor(state.playhead);
      if (frame !== state.frame) {
        state.frame = frame;
        state.dirty = true;
      }
    }
    lastTime = now;
    if (state.dirty || state.backgroundDirty) draw();
    updateReadouts();
  }

  buildPanel();
  bindControls();
  resize();
  updateLegend();
  setPlaying(options.autoplay);
  window.flexkinViewer = {
    get frame() { return state.frame; },
    get playing() { return state.playing; },
    numFrames,
    numPoints,
    dim,
    // The links drawn, as pairs of points [a, b] (a chain's: [k, k + 1]).
    links: Array.from(linkA, (a, k) => [a, linkB[k]]),
    stats,
    view,
    // Where point i of the current frame is drawn, CSS pixels from the canvas's top left.
    pointOnScreen(i) {
      projectPoint(state.frame, i);
      return { x: sx, y: sy };
    },
  };
  requestAnimationFrame(tick);
})();
