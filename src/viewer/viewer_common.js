// The flexkin viewers' shared script: what the chain viewer (viewer.js) and the strands viewer
// (strands_viewer.js) do alike on the page they share (viewer_common.html). flexkin puts this
// script and then the viewer's own into one script element (src/viewer/viewer_page.cc); this one
// only defines flexkinViewerCommon, which the viewer's script uses: the message box, the panel's
// lists of facts, the playback controls (play, previous, next, timeline, speed) and the keys, the
// view's pointer, wheel and resizing, the orbit camera's basis, the draw statistics and the hint.
// What is drawn and how, the data and its decoding, and how playing advances are the viewer's.
const flexkinViewerCommon = (function () {
  'use strict';

  const $ = (id) => document.getElementById(id);

  // Shows `text` in the box over the view (no data, nothing to draw with, ...).
  function showMessage(text) {
    const box = $('message');
    box.textContent = text;
    box.hidden = false;
  }

  // ----- Panel -----------------------------------------------------------------------------------
  // Appends one fact to the <dl> `list`; returns its value's element, to be updated later.
  function addFact(list, name, value) {
    const dt = document.createElement('dt');
    const dd = document.createElement('dd');
    dt.textContent = name;
    dd.textContent = value;
    list.append(dt, dd);
    return dd;
  }

  // Makes the <dl> of id `id` list `rows`, [name, value] pairs, in place of what it listed.
  function fillFacts(id, rows) {
    const list = $(id);
    list.replaceChildren();
    for (const [name, value] of rows) addFact(list, name, value);
  }

  // ----- Orbit camera ----------------------------------------------------------------------------
  const radians = (degrees) => degrees * Math.PI / 180;

  // The 3D view's basis for `azimuth` (about the z axis from the x axis) and `elevation` (above
  // the x-y plane), radians: the screen's right, its up and the direction towards the viewer, 3
  // numbers each, into `out` (9 numbers); returns `out`.
  function orbitBasis(azimuth, elevation, out) {
    const ca = Math.cos(azimuth), sa = Math.sin(azimuth);
    const ce = Math.cos(elevation), se = Math.sin(elevation);
    out.set([-sa, ca, 0, -se * ca, -se * sa, ce, ce * ca, ce * sa, se]);
    return out;
  }

  // A drag of (dx, dy) CSS pixels turns `view`: sideways about the vertical z axis, up and down
  // tilts, the elevation kept within [-90, 90] degrees.
  function orbit(view, dx, dy) {
    view.azimuth -= dx * 0.01;
    view.elevation = Math.max(-Math.PI / 2, Math.min(Math.PI / 2, view.elevation + dy * 0.01));
  }

  // ----- Playback controls and keys --------------------------------------------------------------
  // The speeds of the Speed menu, slowest first.
  const speeds = [0.25, 0.5, 1, 2, 4, 8];
  function showSpeed(speed) {
    $('speed').value = String(speed);
  }
  function showPlaying(playing) {
    $('play').textContent = playing ? 'Pause' : 'Play';
  }

  function isTextField(target) {
    return target instanceof HTMLInputElement && target.type === 'text';
  }

  // Binds the controls both pages have (play, previous, next, timeline, speed, reset view) and
  // the keys. `viewer`: numFrames; frame() and playing(), what is shown; setPlaying(on),
  // setFrame(k), speed() and setSpeed(x), resetView(); scrubPauses: whether moving the timeline
  // pauses; keys: the viewer's own keys, {letter: action}, each letter in lower case and taken
  // with or without shift.
  function bindControls(viewer) {
    const go = (k) => { viewer.setPlaying(false); viewer.setFrame(k); };
    $('timeline').max = String(viewer.numFrames - 1);
    $('play').addEventListener('click', () => viewer.setPlaying(!viewer.playing()));
    $('prev').addEventListener('click', () => go(viewer.frame() - 1));
    $('next').addEventListener('click', () => go(viewer.frame() + 1));
    $('timeline').addEventListener('input', (e) => {
      if (viewer.scrubPauses) viewer.setPlaying(false);
      viewer.setFrame(Number(e.target.value));
    });
    $('speed').addEventListener('change', (e) => viewer.setSpeed(Number(e.target.value)));
    $('reset').addEventListener('click', () => viewer.resetView());

    document.addEventListener('keydown', (e) => {
      if (isTextField(e.target) || e.ctrlKey || e.metaKey || e.altKey) return;
      const jump = e.shiftKey ? 10 : 1;
      const speed = speeds.indexOf(viewer.speed());
      const letter = e.key.length === 1 ? e.key.toLowerCase() : '';
      let handled = true;
      switch (e.key) {
        case ' ': viewer.setPlaying(!viewer.playing()); break;
        case 'ArrowRight': go(viewer.frame() + jump); break;
        case 'ArrowLeft': go(viewer.frame() - jump); break;
        case 'ArrowUp': go(viewer.frame() + 10 * jump); break;
        case 'ArrowDown': go(viewer.frame() - 10 * jump); break;
        case 'Home': go(0); break;
        case 'End': go(viewer.numFrames - 1); break;
        case '+': case '=': viewer.setSpeed(speeds[Math.min(speeds.length - 1, speed + 1)]); break;
        case '-': viewer.setSpeed(speeds[Math.max(0, speed - 1)]); break;
        case 'r': case 'R': viewer.resetView(); break;
        default:
          if (Object.prototype.hasOwnProperty.call(viewer.keys, letter)) viewer.keys[letter]();
          else handled = false;
      }
      if (handled) e.preventDefault();
    });
    // A focused button or checkbox would also act on the space bar's release.
    document.addEventListener('keyup', (e) => {
      if (e.key === ' ' && !isTextField(e.target)) e.preventDefault();
    });
  }

  // ----- The view: pointer, wheel, size ----------------------------------------------------------
  // Dragging on `canvas` orbits `view` (3D) or pans it (2D; in 3D with shift or a button other
  // than the first); the wheel zooms. `hooks`: pan(dx, dy), a drag's move in CSS pixels;
  // orbited(), after orbit() turned the view (optional); zoom(e), for a wheel event; moved(),
  // after every pan, orbit and zoom; click(e), a press and release that moved less than 4 pixels
  // (optional); resize(), whenever the canvas's size changes.
  function bindView(canvas, dim, view, hooks) {
    let drag = null;  // {x, y, moved, pan}
    canvas.addEventListener('pointerdown', (e) => {
      canvas.setPointerCapture(e.pointerId);
      canvas.focus();
      const pan = dim === 2 || e.shiftKey || e.button !== 0;
      drag = { x: e.clientX, y: e.clientY, moved: 0, pan };
      canvas.classList.add('dragging');
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX;
      drag.y = e.clientY;
      drag.moved += Math.abs(dx) + Math.abs(dy);
      if (drag.pan) {
        hooks.pan(dx, dy);
      } else {
        orbit(view, dx, dy);
        if (hooks.orbited) hooks.orbited();
      }
      hooks.moved();
    });
    const end = () => {
      drag = null;
      canvas.classList.remove('dragging');
    };
    canvas.addEventListener('pointerup', (e) => {
      if (!drag) return;
      if (drag.moved < 4 && hooks.click) hooks.click(e);
      end();
    });
    canvas.addEventListener('pointercancel', end);
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      hooks.zoom(e);
      hooks.moved();
    }, { passive: false });
    new ResizeObserver(hooks.resize).observe(canvas);
  }

  // The hint under the view: how the mouse moves it, then `extra` if any.
  function showHint(dim, extra) {
    const moves = dim === 2 ? 'drag: pan \u00b7 wheel: zoom'
                            : 'drag: orbit \u00b7 shift+drag: pan \u00b7 wheel: zoom';
    $('hint').textContent = extra ? moves + ' \u00b7 ' + extra : moves;
  }

  // ----- Statistics, for tests and the curious ---------------------------------------------------
  // Counts a picture drawn since performance.now() was `start` into `stats` (draws, drawMs,
  // maxDrawMs).
  function countDraw(stats, start) {
    const ms = performance.now() - start;
    stats.draws += 1;
    stats.drawMs += ms;
    stats.maxDrawMs = Math.max(stats.maxDrawMs, ms);
  }

  return {
    $, showMessage, addFact, fillFacts, radians, orbitBasis, orbit, speeds, showSpeed, showPlaying,
    isTextField, bindControls, bindView, showHint, countDraw,
  };
})();
