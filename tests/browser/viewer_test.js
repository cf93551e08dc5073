// ctest browser_viewer (browser_viewer_test.sh): pages of `phiq animate -o OUT.html` in headless Chromium.
// For each page: no console error or uncaught exception while it loads, shows frames and plays; screenshots of
// the mechanism at the first and the last frame differ where a point moved (the window around its first position
// changes) and agree on everything away from the mechanism in both (the ground, its pivots, axes, grid); and the
// middle frame, trails and velocity vectors on, matches the committed reference within a tolerance. A page named
// parts_NAME shows parts (solids that sweep the view, so the first and last frames are not compared): its middle
// frame against its reference, and a part named with its pose when picked. A page named clearance_NAME shows a
// scene's output.clearance: its witness points marked, its near parts coloured at a row within the threshold only.
// Usage: node viewer_test.js CHROMIUM REFERENCE_DIR OUT_DIR [--update] [--timing] NAME=PAGE.html ...
//   --update  writes the references (REFERENCE_DIR/NAME.png) instead of comparing with them
//   --timing  also plays each page for 4 s and prints the frame interval and draw time the page measured
'use strict';
const fs = require('fs');
const path = require('path');
const {Browser} = require('./cdp_pipe.js');
const png = require('./png.js');

const [chromium, refDir, outDir, ...rest] = process.argv.slice(2);
const update = rest.includes('--update'), timing = rest.includes('--timing');
const cases = rest.filter((a) => !a.startsWith('--')).map((a) => a.split('='));

let failures = 0;
function check(ok, what) {
  console.log((ok ? 'ok   ' : 'FAIL ') + what);
  if (!ok) ++failures;
}

// Two animation frames: whatever the last command changed is on screen.
const settle = 'new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))';

// The largest channel difference of pixel i between two images.
function diff(a, b, i) {
  return Math.max(Math.abs(a.rgb[3 * i] - b.rgb[3 * i]), Math.abs(a.rgb[3 * i + 1] - b.rgb[3 * i + 1]),
                  Math.abs(a.rgb[3 * i + 2] - b.rgb[3 * i + 2]));
}

// Distance from (x, y) to the segment (a, b).
function toSegment(x, y, a, b) {
  const dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
  const u = l2 > 0 ? Math.max(0, Math.min(1, ((x - a.x) * dx + (y - a.y) * dy) / l2)) : 0;
  return Math.hypot(x - a.x - u * dx, y - a.y - u * dy);
}

// Half size: each pixel the mean of a 2 × 2 block (references stay small, and a pixel of antialiasing counts less).
function half(img) {
  const w = img.width >> 1, h = img.height >> 1, rgb = new Uint8Array(w * h * 3);
  for (let y = 0; y < h; ++y)
    for (let x = 0; x < w; ++x)
      for (let k = 0; k < 3; ++k) {
        const at = (yy, xx) => img.rgb[3 * (yy * img.width + xx) + k];
        rgb[3 * (y * w + x) + k] = (at(2 * y, 2 * x) + at(2 * y, 2 * x + 1) + at(2 * y + 1, 2 * x) + at(2 * y + 1, 2 * x + 1) + 2) >> 2;
      }
  return {width: w, height: h, rgb};
}

// The middle frame with trails and velocity vectors, at half size, against the reference (or written, --update).
async function compareMiddle(tab, name, frames, clip) {
  await tab.evaluate('document.getElementById("trails").checked = true; document.getElementById("vectors").checked = !document.getElementById("vectors").disabled');
  await tab.evaluate(`phiqViewer.show(${Math.floor(frames / 2)})`);
  await tab.evaluate(settle);
  const middle = half(png.decode(await tab.screenshot(clip)));
  const ref = path.join(refDir, `${name}.png`);
  fs.writeFileSync(path.join(outDir, `${name}_middle.png`), png.encode(middle));
  if (update) {
    fs.writeFileSync(ref, png.encode(middle));
    console.log(`wrote ${ref}`);
  } else if (!fs.existsSync(ref)) {
    check(false, `${name}: no reference ${ref} (--update writes it)`);
  } else {
    const want = png.decode(fs.readFileSync(ref));
    check(want.width === middle.width && want.height === middle.height, `${name}: ${middle.width} × ${middle.height} pixels, as the reference`);
    if (want.width === middle.width && want.height === middle.height) {
      let off = 0, sum = 0;
      for (let i = 0; i < want.width * want.height; ++i) {
        const d = diff(want, middle, i);
        off += d > 40, sum += d;
      }
      const n = want.width * want.height;
      check(off <= 0.005 * n && sum / n <= 1.5,
            `${name}: against ${path.basename(ref)}: ${off} pixels differ by more than 40 (at most ${Math.floor(0.005 * n)}), mean difference ${(sum / n).toFixed(3)} (at most 1.5)`);
    }
  }

}

async function testPage(browser, name, page) {
  const tab = await browser.newPage(1280, 720);
  await tab.goto('file://' + path.resolve(page) + '#paused');
  await tab.evaluate(settle);
  const frames = await tab.evaluate('phiqViewer.frames');
  check(frames > 1, `${name}: the page holds ${frames} frames`);
  const view = await tab.evaluate('(() => { const r = document.getElementById("view").firstElementChild.getBoundingClientRect(); return {x: r.left, y: r.top, width: r.width, height: r.height}; })()');
  const clip = {x: Math.round(view.x), y: Math.round(view.y), width: Math.round(view.width), height: Math.round(view.height)};
  if (name.startsWith('clearance_')) {
    // output.clearance: the witness points marked; a pair's parts coloured at a row within the threshold, none at
    // a row where every pair is clear
    const c = await tab.evaluate(`(() => {
      const c = phiq.clearance, rows = c.t.map((t, r) => c.pairs.filter((p) => p.near[r] === '1'));
      const r = rows.findIndex((n) => n.length > 0), clear = rows.findIndex((n) => n.length === 0);
      return {pairs: c.pairs.length, a: r >= 0 ? rows[r][0].a : -1, b: r >= 0 ? rows[r][0].b : -1,
              near: r >= 0 ? phiq.below(phiq.data.t, c.t[r]) : -1, clear: clear >= 0 ? phiq.below(phiq.data.t, c.t[clear]) : -1,
              labels: document.querySelectorAll('text.witness-label').length,
              witness: (document.querySelector('path.witness').getAttribute('d') || '').split('M').length - 1};
    })()`);
    check(c.pairs > 0 && c.labels === c.pairs && c.witness === 3 * c.pairs,
          `${name}: ${c.pairs} pairs, ${c.labels} labels, ${c.witness} witness marks (2 rings and a line each)`);
    check(c.near >= 0 && c.clear >= 0, `${name}: a row within the threshold (frame ${c.near}) and one clear (frame ${c.clear})`);
    await tab.evaluate(`phiqViewer.show(${c.near})`);
    const near = await tab.evaluate('phiqViewer.near()');
    const inked = await tab.evaluate('document.querySelector("path.near").getAttribute("d").length');
    check(near[c.a] === 1 && near[c.b] === 1 && inked > 0, `${name}: at frame ${c.near} parts ${c.a} and ${c.b} are coloured`);
    await tab.evaluate(`phiqViewer.show(${c.clear})`);
    const none = await tab.evaluate('(phiqViewer.near().every((v) => v === 0) && document.querySelector("path.near").getAttribute("d") === "")');
    check(none, `${name}: at frame ${c.clear} no part is coloured`);
    check(tab.errors.length === 0, `${name}: no console error${tab.errors.length ? ': ' + tab.errors.join('; ') : ''}`);
    return;
  }
  if (name.startsWith('parts_')) {
    const first = await tab.evaluate('phiq.parts.names[0]');
    const said = await tab.evaluate('phiqViewer.pick(0)');
    check(said.startsWith(first + ': origin ('), `${name}: picking part 0 names it with its pose: "${said}"`);
    await tab.evaluate('phiqViewer.pick(-1)');
    await compareMiddle(tab, name, frames, clip);
    check(tab.errors.length === 0, `${name}: no console error${tab.errors.length ? ': ' + tab.errors.join('; ') : ''}`);
    return;
  }
  // first and last frame, the mechanism alone (no trails, no vectors)
  await tab.evaluate('document.getElementById("trails").checked = false; document.getElementById("vectors").checked = false');
  const shots = [], points = [];
  for (const k of [0, -1]) {
    await tab.evaluate(`phiqViewer.show(${k})`);
    await tab.evaluate(settle);
    shots.push(png.decode(await tab.screenshot(clip)));
    points.push((await tab.evaluate('phiqViewer.points()')).map((p) => ({...p, x: p.x - clip.x, y: p.y - clip.y})));
  }
  const segments = await tab.evaluate('phiq.data.links.concat(phiq.data.arms)');
  const spatial = (await tab.evaluate('phiq.data.dimension')) === 3;
  const [first, last] = shots;
  fs.writeFileSync(path.join(outDir, `${name}_first.png`), png.encode(first));
  fs.writeFileSync(path.join(outDir, `${name}_last.png`), png.encode(last));

  // where a point moved: the window around its first position changes
  const moved = points[0].map((p, i) => ({p, q: points[1][i]}))
    .filter(({p, q}) => p.moving && Math.hypot(p.x - q.x, p.y - q.y) > 24 && p.x > 3 && p.y > 3 && p.x < clip.width - 4 && p.y < clip.height - 4);
  check(moved.length > 0, `${name}: ${moved.length} points move more than 24 px between the first and the last frame`);
  for (const {p} of moved) {
    let changed = 0;
    for (let y = Math.round(p.y) - 2; y <= Math.round(p.y) + 2; ++y)
      for (let x = Math.round(p.x) - 2; x <= Math.round(p.x) + 2; ++x) changed += diff(first, last, y * clip.width + x) > 64;
    check(changed >= 3, `${name}: around the first position of a moving point (${p.x.toFixed(0)}, ${p.y.toFixed(0)}) ${changed} of 25 pixels change`);
  }
  // the ground: every pixel away from the mechanism in both frames (lines, joints, their shading) is the same
  const reach = spatial ? 22 : 9, near = [];
  for (const pts of points) {
    for (let k = 0; k < segments.length; k += 2) near.push([pts[segments[k]], pts[segments[k + 1]]]);
    for (const p of pts) if (p.moving) near.push([p, p]);
  }
  let compared = 0, differing = 0, inked = 0;
  for (let y = 0; y < clip.height; ++y)
    for (let x = 0; x < clip.width; ++x) {
      if (near.some(([a, b]) => toSegment(x, y, a, b) < reach)) continue;
      const i = y * clip.width + x;
      ++compared;
      differing += diff(first, last, i) > 32;
      inked += first.rgb[3 * i] < 240 || first.rgb[3 * i + 1] < 240 || first.rgb[3 * i + 2] < 240;
    }
  check(compared > 0.5 * clip.width * clip.height && inked > 2000,
        `${name}: ${compared} pixels away from the mechanism compared, ${inked} of them not white (ground, axes, grid)`);
  check(differing <= 0.0005 * compared, `${name}: ${differing} of them differ between the first and the last frame (at most 0.05 %)`);
  // fixed points stay put on screen
  const fixed = points[0].filter((p, i) => !p.moving && Math.hypot(p.x - points[1][i].x, p.y - points[1][i].y) < 0.5);
  check(fixed.length === points[0].filter((p) => !p.moving).length, `${name}: the ${fixed.length} fixed points stay where they are`);

  await compareMiddle(tab, name, frames, clip);

  // it plays: the clock moves the pose (the slider), and nothing goes wrong on the way
  const before = await tab.evaluate('document.getElementById("time").value');
  await tab.evaluate('phiqViewer.play()');
  await tab.evaluate('new Promise((r) => setTimeout(r, timing ? 4000 : 600))'.replace('timing', String(timing)));
  const after = await tab.evaluate('phiqViewer.pause(), document.getElementById("time").value');
  check(before !== after, `${name}: playing moves the time slider (${before} to ${after})`);
  if (timing) console.log(`${name}: ${JSON.stringify(await tab.evaluate('phiqViewer.timing()'))}`);
  check(tab.errors.length === 0, `${name}: no console error${tab.errors.length ? ': ' + tab.errors.join('; ') : ''}`);
}

(async () => {
  fs.mkdirSync(outDir, {recursive: true});
  const browser = new Browser(chromium, {timeoutMs: 30000});
  try {
    for (const [name, page] of cases) await testPage(browser, name, page);
  } catch (e) {
    check(false, String(e.stack || e));
  } finally {
    await browser.close();
  }
  console.log(failures ? `${failures} checks failed` : 'all checks passed');
  process.exit(failures ? 1 : 0);
})();
