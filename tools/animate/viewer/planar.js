// phiq animate's planar view: the mechanism in SVG over the still background phiq drew (axes with units, the
// hatched ground under fixed pivots: tools/plot/plot_mechanism.cpp, as `phiq plot` draws them). Each pose redraws a
// few <path> elements, one per kind of mark (links, revolute pins, prismatic blocks, ...), whatever the number of
// loops, and only what the pixels can show (pairs(), Sparse below): a 10^4-loop chain is a handful of elements of
// a few hundred strokes, not 10^5 elements. The marks are phiq plot's: pins white circles, sliders blocks on their
// guides, link ends dots. Under them the parts: a filled outline per shape (a path per shape of each distinct
// geometry, holding every part that shares it), their frames on request, the part under the pointer named.
'use strict';

(function () {
  const d = phiq.data, b = d.box, P = d.points;
  const NS = 'http://www.w3.org/2000/svg';
  const svg = document.getElementById('mechanism-svg'), layer = document.getElementById('moving');
  const kx = b.w / (b.xmax - b.xmin), ky = b.h / (b.ymax - b.ymin);
  function path(cls, attrs) {
    const e = document.createElementNS(NS, 'path');
    e.setAttribute('class', cls);
    for (const k in attrs) e.setAttribute(k, attrs[k]);
    layer.appendChild(e);
    return e;
  }
  // drawn bottom to top: parts, trails, guides, lines, marks, vectors
  const parts = phiq.parts, N = parts.names.length;
  const members = parts.geometries.map(() => []);
  parts.geometry.forEach((g, k) => members[g].push(k));
  const partPaths = parts.geometries.map((shapes) => shapes.map((sh) => sh.width !== undefined
    ? path('part', {fill: 'none', stroke: sh.colour, 'stroke-width': Math.max(1, sh.width * kx), 'stroke-linejoin': 'round'})
    : path('part', {fill: sh.colour, 'fill-opacity': 0.55, stroke: sh.colour, 'stroke-width': 1})));
  // the parts within the clearance threshold at the time shown, over their own colours
  const nearPath = path('part near', {fill: '#d62728', 'fill-opacity': 0.7, stroke: '#d62728', 'stroke-width': 2});
  const partAxes = [path('part-frame', {fill: 'none', stroke: '#d62728', 'stroke-width': 1.5}),
                    path('part-frame', {fill: 'none', stroke: '#2ca02c', 'stroke-width': 1.5})];
  const sx = (x) => b.x0 + (x - b.xmin) * kx, sy = (y) => b.y0 + b.h - (y - b.ymin) * ky;
  // Level of detail, as for the lines below: a shape whose outline spans under a pixel is not drawn (a 10^4-loop
  // chain's links are a tenth of a pixel: 3·10^4 outlines a frame cost 200 ms and showed nothing the lines do not)
  const reach = parts.geometries.map((shapes) => shapes.map((sh) => {
    let r = sh.width ? sh.width : 0;
    for (let v = 0; v < sh.outline.length; v += 2) r = Math.max(r, Math.hypot(sh.outline[v], sh.outline[v + 1]));
    return r;
  }));
  function drawParts(place, frames, near) {
    const axes = [[], []], nearD = [];
    partPaths.forEach((shapes, g) => shapes.forEach((el, i) => {
      const sh = parts.geometries[g][i], o = sh.outline, d = [];
      if (2 * reach[g][i] * Math.max(kx, ky) < 1) return el.setAttribute('d', '');
      for (const k of members[g]) {
        const x0 = place[7 * k], y0 = place[7 * k + 1], a = 2 * Math.atan2(place[7 * k + 5], place[7 * k + 6]);
        const c = Math.cos(a), s = Math.sin(a), to = near[k] ? [d, nearD] : [d];
        for (const list of to) {
          for (let v = 0; v < o.length; v += 2)
            list.push((v ? 'L' : 'M') + r1(sx(x0 + c * o[v] - s * o[v + 1])) + ' ' + r1(sy(y0 + s * o[v] + c * o[v + 1])));
          if (sh.width === undefined || sh.closed) list.push('Z');
        }
      }
      el.setAttribute('d', d.join(''));
    }));
    if (frames)
      for (let k = 0; k < N; ++k) {
        const X0 = sx(place[7 * k]), Y0 = sy(place[7 * k + 1]), a = 2 * Math.atan2(place[7 * k + 5], place[7 * k + 6]);
        axes[0].push('M' + r1(X0) + ' ' + r1(Y0) + 'l' + r1(24 * Math.cos(a)) + ' ' + r1(-24 * Math.sin(a)));
        axes[1].push('M' + r1(X0) + ' ' + r1(Y0) + 'l' + r1(-24 * Math.sin(a)) + ' ' + r1(-24 * Math.cos(a)));
      }
    partAxes[0].setAttribute('d', axes[0].join('')), partAxes[1].setAttribute('d', axes[1].join(''));
    nearPath.setAttribute('d', nearD.join(''));
  }
  // the part under the pointer: the last drawn whose outline holds the point (a curve: within its half width)
  let shown = null;
  function partAt(event) {
    const m = svg.getScreenCTM().inverse(), pt = svg.createSVGPoint();
    pt.x = event.clientX, pt.y = event.clientY;
    const u = pt.matrixTransform(m), wx = b.xmin + (u.x - b.x0) / kx, wy = b.ymin + (b.y0 + b.h - u.y) / ky;
    const place = shown;
    for (let k = N - 1; k >= 0 && place; --k) {
      const a = 2 * Math.atan2(place[7 * k + 5], place[7 * k + 6]), c = Math.cos(a), s = Math.sin(a);
      const dx = wx - place[7 * k], dy = wy - place[7 * k + 1], px = c * dx + s * dy, py = -s * dx + c * dy;
      for (const sh of parts.geometries[parts.geometry[k]]) {
        const o = sh.outline;
        let inside = false;
        if (sh.width === undefined) {
          for (let i = 0, j = o.length - 2; i < o.length; j = i, i += 2)
            if ((o[i + 1] > py) !== (o[j + 1] > py) && px < o[i] + (py - o[i + 1]) * (o[j] - o[i]) / (o[j + 1] - o[i + 1])) inside = !inside;
        } else {
          for (let i = 2; i < o.length && !inside; i += 2) {
            const ex = o[i] - o[i - 2], ey = o[i + 1] - o[i - 1], l2 = ex * ex + ey * ey;
            const t = l2 > 0 ? Math.max(0, Math.min(1, ((px - o[i - 2]) * ex + (py - o[i - 1]) * ey) / l2)) : 0;
            inside = Math.hypot(px - o[i - 2] - t * ex, py - o[i - 1] - t * ey) <= Math.max(sh.width / 2, 3 / kx);
          }
        }
        if (inside) return k;
      }
    }
    return -1;
  }
  if (N) {
    svg.addEventListener('mousemove', (e) => phiq.pick(partAt(e)));
    svg.addEventListener('click', (e) => phiq.pick(partAt(e)));
  }
  const trails = phiq.traces.map((tr) => path('trail', {fill: 'none', stroke: tr.colour, 'stroke-width': 1.5,
                                                        'data-point': tr.name}));
  const guides = path('guide', {fill: 'none', stroke: '#222', 'stroke-width': 1});
  const hatches = path('hatch', {fill: 'none', stroke: '#222', 'stroke-width': 1});
  const arms = path('arm', {fill: 'none', stroke: '#222', 'stroke-width': 2, 'stroke-linecap': 'round'});
  const links = path('link', {fill: 'none', stroke: '#222', 'stroke-width': 2, 'stroke-linecap': 'round'});
  const blocks = path('joint prismatic', {fill: 'white', stroke: '#222', 'stroke-width': 1.5});
  const pins = path('joint revolute', {fill: 'white', stroke: '#222', 'stroke-width': 1.5});
  const balls = path('joint spherical', {fill: '#222', stroke: '#222', 'stroke-width': 1.5});
  const dots = path('joint point', {fill: '#222', stroke: 'none'});
  const vectors = path('velocity', {fill: 'none', stroke: '#cc00cc', 'stroke-width': 1.5});
  const heads = path('velocity-head', {fill: '#cc00cc', stroke: 'none'});
  // forces (phiq animate --forces): reactions orange, efforts red; a moment an arc of 270 degrees about its point
  const F = d.forces || {scale: 0, arrows: []};
  const forceLines = ['reaction', 'effort'].map((k, i) => path('force ' + k, {fill: 'none', stroke: i ? '#d62728' : '#ff7f0e', 'stroke-width': 2}));
  const forceHeads = ['reaction', 'effort'].map((k, i) => path('force-head ' + k, {fill: i ? '#d62728' : '#ff7f0e', stroke: 'none'}));
  function head(ex, ey, ux, uy) {
    return 'M' + r1(ex) + ' ' + r1(ey) + 'L' + r1(ex - 8 * ux + 3.5 * uy) + ' ' + r1(ey - 8 * uy - 3.5 * ux) + 'L' +
           r1(ex - 8 * ux - 3.5 * uy) + ' ' + r1(ey - 8 * uy + 3.5 * ux) + 'Z';
  }
  function drawForces(frame, show) {
    const lines = [[], []], tips = [[], []];
    if (show)
      for (const a of F.arrows) {
        const i = a.kind === 'effort' ? 1 : 0, x = sx(a.at[3 * frame]), y = sy(a.at[3 * frame + 1]);
        const fx = a.force[3 * frame], fy = a.force[3 * frame + 1], mz = a.moment[3 * frame + 2];
        if (fx !== null && fy !== null) {
          const vx = fx * F.scale * kx, vy = -fy * F.scale * ky, n = Math.hypot(vx, vy);
          if (n >= 2) {
            lines[i].push('M' + r1(x) + ' ' + r1(y) + 'l' + r1(vx) + ' ' + r1(vy));
            tips[i].push(head(x + vx, y + vy, vx / n, vy / n));
          }
        }
        const r = mz === null ? 0 : Math.abs(mz) * F.scale * kx;
        if (r >= 2) {
          // from angle 0 through 270 degrees, counter-clockwise on the page for a positive moment about z
          // ending below the point (counter-clockwise) or above it (clockwise), heading right either way
          const ex = x, ey = mz > 0 ? y + r : y - r;
          lines[i].push('M' + r1(x + r) + ' ' + r1(y) + 'A' + r1(r) + ' ' + r1(r) + ' 0 1 ' + (mz > 0 ? 0 : 1) + ' ' + r1(ex) + ' ' + r1(ey));
          tips[i].push(head(ex, ey, 1, 0));
        }
      }
    for (let i = 0; i < 2; ++i) forceLines[i].setAttribute('d', lines[i].join('')), forceHeads[i].setAttribute('d', tips[i].join(''));
  }
  const legend = document.createElementNS(NS, 'g');
  phiq.traces.forEach((tr, k) => {
    const text = document.createElementNS(NS, 'text');
    text.setAttribute('x', b.x0 + 6), text.setAttribute('y', b.y0 + 16 + 14 * k), text.setAttribute('fill', tr.colour);
    text.setAttribute('class', 'legend');
    text.textContent = tr.name;
    legend.appendChild(text);
  });
  layer.appendChild(legend);

  const X = new Float32Array(P), Y = new Float32Array(P), J = d.joints.p.length;
  const prismatic = {};
  for (const j of d.prismatic) prismatic[j.joint] = j;
  const r1 = (v) => Math.round(v * 10) / 10;
  function circle(x, y, r) { return 'M' + r1(x - r) + ' ' + r1(y) + 'a' + r + ' ' + r + ' 0 1 0 ' + 2 * r + ' 0a' + r + ' ' + r + ' 0 1 0 ' + -2 * r + ' 0'; }
  // each clearance pair's witness points at its worst pose: two rings and the line between, numbered; the numbers
  // listed at the panel's foot with the pair, its distance and time
  const witness = path('witness', {fill: 'none', stroke: '#d62728', 'stroke-width': 1.5});
  if (phiq.clearance) {
    const w = [], n = phiq.clearance.pairs.length;
    const text = (x, y, cls, words) => {
      const e = document.createElementNS(NS, 'text');
      e.setAttribute('x', r1(x)), e.setAttribute('y', r1(y)), e.setAttribute('fill', '#d62728');
      e.setAttribute('class', cls);
      e.textContent = words;
      layer.appendChild(e);
    };
    phiq.clearance.pairs.forEach((pair, k) => {
      const ax = sx(pair.point_a[0]), ay = sy(pair.point_a[1]), bx = sx(pair.point_b[0]), by = sy(pair.point_b[1]);
      w.push(circle(ax, ay, 4), circle(bx, by, 4), 'M' + r1(ax) + ' ' + r1(ay) + 'L' + r1(bx) + ' ' + r1(by));
      text(Math.max(ax, bx) + 6, Math.min(ay, by) - 4 - 12 * (k % 2), 'witness-number', String(k + 1));
      text(b.x0 + 6, b.y0 + b.h - 6 - 14 * (n - 1 - k), 'witness-label', (k + 1) + ' ' + pair.name + ': ' +
           (+pair.distance).toPrecision(3) + ' m at t = ' + (+pair.worst_t).toPrecision(4) + ' s');
    });
    witness.setAttribute('d', w.join(''));
  }
  // Level of detail: what the panel's pixels can show, whatever the number of loops. A line is drawn once per
  // pair of end pixels (10^4 cranks 0.05 px apart are one stroke), and a mark or an arrow only where no other
  // lies within `cell` pixels; lines and marks outside the panel are left out. Small mechanisms lose nothing.
  const left = b.x0, right = b.x0 + b.w, top = b.y0, bottom = b.y0 + b.h;
  const drawn = new Set();
  function pairs(list) {
    const s = [];
    drawn.clear();
    for (let k = 0; k < list.length; k += 2) {
      const i = list[k], j = list[k + 1];
      const x1 = X[i], y1 = Y[i], x2 = X[j], y2 = Y[j];
      if ((x1 < left && x2 < left) || (x1 > right && x2 > right) || (y1 < top && y2 < top) || (y1 > bottom && y2 > bottom)) continue;
      const a = Math.round(x1) + 4096 * Math.round(y1), c = Math.round(x2) + 4096 * Math.round(y2);
      const key = a < c ? a * 16777216 + c : c * 16777216 + a;
      if (drawn.has(key)) continue;
      drawn.add(key);
      s.push('M' + r1(x1) + ' ' + r1(y1) + 'L' + r1(x2) + ' ' + r1(y2));
    }
    return s.join('');
  }
  function Sparse(cell) {
    const nx = Math.ceil(b.w / cell) + 1, ny = Math.ceil(b.h / cell) + 1, used = new Uint8Array(nx * ny);
    return {
      clear() { used.fill(0); },
      // true the first time a cell is asked for; false outside the panel
      take(x, y) {
        const i = Math.floor((x - left) / cell), j = Math.floor((y - top) / cell);
        if (i < 0 || j < 0 || i >= nx || j >= ny || used[i + nx * j]) return false;
        used[i + nx * j] = 1;
        return true;
      },
    };
  }
  const marksGrid = Sparse(3), arrowsGrid = Sparse(12);
  // the largest speed drawn 60 pixels long
  const vscale = d.vmax > 0 ? 60 / (d.vmax * kx) : 0;

  phiq.start({
    draw(p, show) {
      shown = p.parts;
      drawParts(p.parts, show.frames, p.near);
      const pos = p.pos;
      for (let i = 0; i < P; ++i) {
        X[i] = b.x0 + (pos[2 * i] - b.xmin) * kx;
        Y[i] = b.y0 + b.h - (pos[2 * i + 1] - b.ymin) * ky;
      }
      links.setAttribute('d', pairs(d.links));
      arms.setAttribute('d', pairs(d.arms));
      const pin = [], ball = [], dot = [], block = [], guide = [], hatch = [];
      marksGrid.clear();
      for (let k = 0; k < J; ++k) {
        const x = X[d.joints.p[k]], y = Y[d.joints.p[k]], mark = d.joints.marks[k];
        if (!marksGrid.take(x, y)) continue;
        if (mark === 'p') {
          const j = prismatic[k] || {};
          // the block along its guide, 18 x 10 px, the guide through it; hatched below a guide on the ground
          const a = j.angles ? j.angles[p.frame] : (j.angle || 0), ux = Math.cos(a), uy = -Math.sin(a);
          guide.push('M' + r1(x - 26 * ux) + ' ' + r1(y - 26 * uy) + 'L' + r1(x + 26 * ux) + ' ' + r1(y + 26 * uy));
          const c = [[-9, -5], [9, -5], [9, 5], [-9, 5]].map(([u, v]) => r1(x + u * ux - v * uy) + ' ' + r1(y + u * uy + v * ux));
          block.push('M' + c.join('L') + 'Z');
          if (j.ground_guide)
            for (let k = -2; k <= 2; ++k) {
              const hx = x + 10 * k * ux, hy = y + 10 * k * uy;
              hatch.push('M' + r1(hx + 7 * uy) + ' ' + r1(hy - 7 * ux) + 'l' + r1(-5 * ux) + ' ' + r1(-5 * uy));
            }
        } else if (mark === 'o') {
          dot.push(circle(x, y, 2.5));
        } else {
          (mark === 's' ? ball : pin).push(circle(x, y, 4));
        }
      }
      pins.setAttribute('d', pin.join('')), balls.setAttribute('d', ball.join('')), dots.setAttribute('d', dot.join(''));
      blocks.setAttribute('d', block.join('')), guides.setAttribute('d', guide.join(''));
      hatches.setAttribute('d', hatch.join(''));
      phiq.traces.forEach((tr, k) => {
        const s = [];
        if (show.trails)
          for (let i = 0; i < p.samples; ++i)
            s.push((i ? 'L' : 'M') + r1(b.x0 + (tr.pos[2 * i] - b.xmin) * kx) + ' ' +
                   r1(b.y0 + b.h - (tr.pos[2 * i + 1] - b.ymin) * ky));
        trails[k].setAttribute('d', s.join(''));
      });
      const v = [], h = [];
      arrowsGrid.clear();
      if (show.vectors && p.vel)
        for (let i = 0; i < P; ++i) {
          if (d.moving[i] !== '1' || !arrowsGrid.take(X[i], Y[i])) continue;
          const vx = p.vel[2 * i] * kx * vscale, vy = -p.vel[2 * i + 1] * ky * vscale, n = Math.hypot(vx, vy);
          if (n < 2) continue;
          const ex = X[i] + vx, ey = Y[i] + vy, ux = vx / n, uy = vy / n;
          v.push('M' + r1(X[i]) + ' ' + r1(Y[i]) + 'L' + r1(ex) + ' ' + r1(ey));
          h.push('M' + r1(ex) + ' ' + r1(ey) + 'L' + r1(ex - 7 * ux + 3 * uy) + ' ' + r1(ey - 7 * uy - 3 * ux) + 'L' +
                 r1(ex - 7 * ux - 3 * uy) + ' ' + r1(ey - 7 * uy + 3 * ux) + 'Z');
        }
      vectors.setAttribute('d', v.join('')), heads.setAttribute('d', h.join(''));
      drawForces(p.frame, show.forces);
    },
    // where each point is on the page (CSS pixels), and whether it moves: for scripts checking screenshots
    screenPoints(pos) {
      const m = svg.getScreenCTM(), q = svg.createSVGPoint(), out = [];
      for (let i = 0; i < P; ++i) {
        q.x = b.x0 + (pos[2 * i] - b.xmin) * kx, q.y = b.y0 + b.h - (pos[2 * i + 1] - b.ymin) * ky;
        const s = q.matrixTransform(m);
        out.push({x: s.x, y: s.y, moving: d.moving[i] === '1'});
      }
      return out;
    },
  });
})();
