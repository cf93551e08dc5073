// phiq animate's viewer, shared by both views: it reads the data `phiq animate` wrote (the JSON of #phiq-data),
// keeps the clock (play/pause, the time slider, the speed), interpolates the pose between the rows it holds, moves
// the cursor over the plots, and hands every pose to the view, planar.js (SVG) or spatial.js (WebGL), which calls
// phiq.start(view) once it is built.
//
// The data (tools/animate/html_motion.cpp writes it):
//   dimension      2 or 3: components of every position
//   rows, kept     the result's row count; the rows held as frames (first and last included, evenly spread)
//   t              t at each frame (s)
//   points         P, the distinct points of the mechanism's sketch (ends of its lines, its joints)
//   moving         a character per point: 1 if it reads a coordinate, 0 if it is fixed to the ground
//   frames         base64 of little-endian int16: frame-major, P points of `dimension` components each, the value
//                  lo[c] + (code + 32767) (hi[c] - lo[c]) / 65534
//   velocities     the same layout over [-vmax, vmax] (null when the result has no velocity columns)
//   links, arms    point index pairs: a link of the sketch, a body's arm (its reference point to an attachment)
//   joints         columns {p: point index, marks: a letter per joint (r revolute, p prismatic, s spherical, o the
//                  end of a link), fixed: a character per joint, 1 for a ground pivot}
//   prismatic      the planar prismatic pairs: {joint, angle or angles (per frame: the guide's direction, rad),
//                  ground_guide}
//   traces, trace_t  the traced output points ({name, colour, data: the frames' encoding}) at the times trace_t
//   plot_t         the t range of the plots' axes (their cursor); box: the planar view's pixel box (planar.js)
//   velocity_note  why there are no velocity vectors, when there are none
//   row_labels     a label per row when the rows are separate poses (phiq animate --modes): the nearest frame is
//                  shown as it is, never interpolated, and its label replaces the time
//   forces         with `phiq animate --forces SCALE` (tools/animate/force_arrows.hpp): {scale: m per N (and per
//                  N m: a moment's arc radius in the plane, its arrow's length in space), arrows: [{name, kind
//                  (reaction or effort), at, force, moment: 3 values per kept row each (world axes; null at a
//                  singular row)}], unplaced: the efforts not drawn (no joint to draw them at)}
//   parts          the parts drawn (phiq/drawn_parts.hpp): {names, shapes: per part its shapes' names, geometry: a
//                  geometry index per part, fixed: a character per part, geometries: per geometry its shapes ({colour,
//                  and in space p: base64 float32 x, y, z per vertex, i: base64 uint32 three per triangle; in the
//                  plane outline: x, y, ... in the part's frame, width and closed for a curve}), poses: base64 int16,
//                  frame-major, 7 per part (origin over parts.lo .. parts.hi, quaternion x, y, z, w over -1 .. 1)}
//   clearance      the scene's output.clearance, when it has one (tools/animate/html_clearance.cpp): {threshold,
//                  t: its sweep's rows' times, pairs: [{a, b: part indices, name, worst_t, distance, point_a,
//                  point_b: the witness points at the worst pose (x, y, z), near: a character per row, 1 where the
//                  pair comes within the threshold in the row's span (on the row, at a minimum or an interference
//                  interval between rows), interference: [[entry, exit], …]}]}; the views mark the witness points
//                  and colour the near parts
'use strict';

const phiq = (function () {
  const data = JSON.parse(document.getElementById('phiq-data').textContent);
  const D = data.dimension, P = data.points, T = data.t, F = T.length;

  // int16 codes (base64) onto [lo, hi] per component
  function decode(b64, lo, hi) {
    const bin = atob(b64), n = bin.length >> 1, out = new Float32Array(n), D = lo.length;
    const step = lo.map((l, c) => (hi[c] - l) / 65534);
    for (let i = 0; i < n; ++i) {
      let code = bin.charCodeAt(2 * i) | (bin.charCodeAt(2 * i + 1) << 8);
      if (code >= 32768) code -= 65536;
      const c = i % D;
      out[i] = lo[c] + (code + 32767) * step[c];
    }
    return out;
  }
  const frames = decode(data.frames, data.lo, data.hi);
  const vmaxes = new Array(D).fill(data.vmax);
  const velocities = data.velocities ? decode(data.velocities, vmaxes.map((v) => -v), vmaxes) : null;
  const parts = data.parts || {names: [], geometry: [], geometries: [], fixed: '', poses: '', lo: [], hi: []};
  const N = parts.names.length;
  const partFrames = N ? decode(parts.poses, parts.lo.concat([-1, -1, -1, -1]), parts.hi.concat([1, 1, 1, 1])) : null;
  const traces = data.traces.map((tr) => ({name: tr.name, colour: tr.colour, pos: decode(tr.data, data.lo, data.hi)}));

  // the last index i with a[i] <= x (0 if none)
  function below(a, x) {
    let lo = 0, hi = a.length - 1;
    if (!(x >= a[0])) return 0;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (a[mid] <= x) lo = mid; else hi = mid - 1;
    }
    return lo;
  }

  // the parts of the pairs within the clearance threshold at time t: those of the row of the clearance sweep nearest t
  const clearance = data.clearance || null, near = new Uint8Array(N);
  function nearAt(t) {
    near.fill(0);
    if (!clearance || !clearance.t.length) return near;
    const ct = clearance.t;
    let r = below(ct, t);
    if (r + 1 < ct.length && ct[r + 1] - t < t - ct[r]) r += 1;
    for (const pair of clearance.pairs) if (pair.near[r] === '1') near[pair.a] = near[pair.b] = 1;
    return near;
  }

  const pos = new Float32Array(P * D), vel = velocities ? new Float32Array(P * D) : null, place = new Float32Array(7 * N);
  // The pose at time t: linear between the frames around it.
  function pose(t) {
    let i = Math.min(below(T, t), F - 1), j = Math.min(i + 1, F - 1);
    let w = j > i && T[j] > T[i] ? Math.min(1, Math.max(0, (t - T[i]) / (T[j] - T[i]))) : 0;
    if (data.row_labels) i = j = w < 0.5 ? i : j, w = 0;  // separate poses: the nearest, as it is
    const a = i * P * D, b = j * P * D;
    for (let k = 0; k < P * D; ++k) pos[k] = frames[a + k] + w * (frames[b + k] - frames[a + k]);
    if (vel) for (let k = 0; k < P * D; ++k) vel[k] = velocities[a + k] + w * (velocities[b + k] - velocities[a + k]);
    // the parts: origins linear, quaternions normalised linear (consecutive frames share a sign)
    for (let k = 0; k < 7 * N; k += 7) {
      const pa = i * 7 * N + k, pb = j * 7 * N + k;
      let n = 0;
      for (let c = 0; c < 7; ++c) {
        place[k + c] = partFrames[pa + c] + w * (partFrames[pb + c] - partFrames[pa + c]);
        if (c >= 3) n += place[k + c] * place[k + c];
      }
      n = Math.sqrt(n) || 1;
      for (let c = 3; c < 7; ++c) place[k + c] /= n;
    }
    return {t, frame: w < 0.5 ? i : j, pos, vel, parts: place, near: nearAt(t), samples: data.trace_t.length ? below(data.trace_t, t) + 1 : 0};
  }

  // ---- controls
  const play = document.getElementById('play'), slider = document.getElementById('time');
  const timeText = document.getElementById('time-value'), speedSelect = document.getElementById('speed');
  const trails = document.getElementById('trails'), vectors = document.getElementById('vectors');
  const partFramesBox = document.getElementById('part-frames'), partInfo = document.getElementById('part-info');
  if (!N) partFramesBox.disabled = true;
  const forcesBox = document.getElementById('forces');
  if (data.forces) forcesBox.checked = true; else forcesBox.disabled = true;
  const t0 = T[0], t1 = T[F - 1], span = t1 - t0;
  // speed: simulated seconds per second; the default plays the whole result in about 8 s
  const speeds = [0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100, 200, 500, 1000];
  let best = 9;
  if (span > 0) for (let k = 0; k < speeds.length; ++k)
    if (Math.abs(Math.log(speeds[k] * 8 / span)) < Math.abs(Math.log(speeds[best] * 8 / span))) best = k;
  speeds.forEach((s, k) => {
    const o = document.createElement('option');
    o.value = s;
    o.textContent = s + '\u00d7' + (s === 1 ? ' (real time)' : '');
    if (k === best) o.selected = true;
    speedSelect.appendChild(o);
  });
  if (!vel) {
    vectors.disabled = true;
    document.getElementById('note').textContent = data.velocity_note || '';
  }
  if (!traces.length) trails.disabled = true, trails.checked = false;

  // ---- the plots' cursor: a line over each panel, at t along its frame
  const cursors = [];
  document.querySelectorAll('#plots .panel').forEach((panel) => {
    const frame = panel.querySelector('rect.frame');
    if (!frame) return;
    const x = +frame.getAttribute('x'), y = +frame.getAttribute('y');
    const w = +frame.getAttribute('width'), h = +frame.getAttribute('height');
    const line = document.createElementNS('http://www.w3.org/2000/svg', 'line');
    line.setAttribute('class', 'cursor');
    line.setAttribute('y1', y), line.setAttribute('y2', y + h);
    line.setAttribute('stroke', '#d00'), line.setAttribute('stroke-width', '1');
    panel.appendChild(line);
    cursors.push({line, x, w});
  });
  const pt = data.plot_t || [t0, t1];

  let view = null, t = t0, playing = false, dirty = true;
  const intervals = [], drawTimes = [];
  function render() {
    const p = pose(t);
    const started = performance.now();
    view.draw(p, {trails: trails.checked, vectors: vectors.checked && !!vel, frames: partFramesBox.checked,
                  forces: forcesBox.checked && !!data.forces});
    if (picked >= 0) describe(picked, p.parts);
    drawTimes.push(performance.now() - started);
    if (drawTimes.length > 600) drawTimes.shift();
    const u = span > 0 ? (t - t0) / span : 0;
    slider.value = Math.round(u * 10000);
    timeText.textContent = data.row_labels ? data.row_labels[data.kept[p.frame]]
      : 't = ' + t.toPrecision(5) + ' s \u00b7 row ' + (data.kept[p.frame] + 1) + '/' + data.rows;
    const f = pt[1] > pt[0] ? (t - pt[0]) / (pt[1] - pt[0]) : 0;
    for (const c of cursors) {
      const x = c.x + f * c.w;
      c.line.setAttribute('x1', x), c.line.setAttribute('x2', x);
    }
    dirty = false;
  }
  function setPlaying(on) {
    playing = on && F > 1 && span > 0;
    play.innerHTML = playing ? '&#10074;&#10074; pause' : '&#9654; play';
  }
  let last = null;
  function tick(now) {
    if (last !== null) {
      intervals.push(now - last);
      if (intervals.length > 600) intervals.shift();
    }
    if (playing) {
      if (last !== null) {
        t += (now - last) / 1000 * +speedSelect.value;
        if (t > t1) t = t0 + ((t - t0) % span);  // loop
      }
      dirty = true;
    }
    last = now;
    if (dirty) render();
    requestAnimationFrame(tick);
  }
  play.addEventListener('click', () => setPlaying(!playing));
  document.addEventListener('keydown', (e) => {
    if (e.key === ' ' && e.target.tagName !== 'BUTTON') { e.preventDefault(); setPlaying(!playing); }
  });
  slider.addEventListener('input', () => { setPlaying(false); t = t0 + span * slider.value / 10000; dirty = true; });
  for (const box of [trails, vectors, partFramesBox, forcesBox]) box.addEventListener('change', () => { dirty = true; });

  // the part under the pointer (the view finds it): its name and pose at the time shown
  let picked = -1;
  function describe(k, place) {
    const f = (v) => (+v).toPrecision(4), o = 7 * k;
    const at = 'origin (' + Array.from(place.slice(o, o + D), f).join(', ') + ') m';
    const q = place.slice(o + 3, o + 7), angle = 2 * Math.atan2(Math.hypot(q[0], q[1], q[2]), q[3]);
    let turn;
    if (D === 2) {
      turn = 'angle ' + f(2 * Math.atan2(q[2], q[3]) * 180 / Math.PI) + '\u00b0';
    } else {
      const s = Math.hypot(q[0], q[1], q[2]) || 1;
      turn = 'turned ' + f(angle * 180 / Math.PI) + '\u00b0 about (' + [q[0] / s, q[1] / s, q[2] / s].map(f).join(', ') + ')';
    }
    partInfo.textContent = parts.names[k] + ': ' + at + ', ' + turn;
  }
  function pick(k) {
    picked = k;
    if (k < 0) partInfo.textContent = ''; else describe(k, pose(t).parts);
  }

  function stats(list) {
    if (!list.length) return null;
    const s = list.slice().sort((a, b) => a - b);
    return {count: s.length, mean: s.reduce((a, b) => a + b, 0) / s.length, median: s[s.length >> 1],
            p95: s[Math.floor(0.95 * (s.length - 1))], max: s[s.length - 1]};
  }

  return {
    data, traces, below, parts, pick, clearance,
    // Called by the view once built: draws the first pose and starts the clock. The page's address may ask for a
    // frame and a still picture: #frame=K (K a frame index, or "last"), paused.
    start(v) {
      view = v;
      const hash = new URLSearchParams(location.hash.slice(1));
      if (hash.has('frame')) t = T[hash.get('frame') === 'last' ? F - 1 : Math.max(0, Math.min(F - 1, +hash.get('frame')))];
      if (hash.has('vectors') && vel) vectors.checked = true;
      setPlaying(!hash.has('paused'));
      render();
      requestAnimationFrame(tick);
      // for scripts driving the page (tests/browser/): show a frame still, where the points are on screen, timing
      window.phiqViewer = {
        frames: F,
        show(k) { setPlaying(false); t = T[k < 0 ? F + k : k]; render(); return t; },
        play() { intervals.length = drawTimes.length = 0; last = null; setPlaying(true); },
        pause() { setPlaying(false); },
        points() { return view.screenPoints(pose(t).pos); },
        pick(k) { pick(k); return partInfo.textContent; },
        near() { return Array.from(nearAt(t)); },
        timing() { return {frameInterval: stats(intervals), draw: stats(drawTimes)}; },
      };
    },
  };
})();
