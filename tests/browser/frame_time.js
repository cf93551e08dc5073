// How smoothly a page of `phiq animate -o OUT.html` plays in headless Chromium: it plays for SECONDS (default 5)
// and prints what the page itself measured (viewer.js: phiqViewer.timing()): the intervals between animation
// frames and the time each pose took to draw, in ms. A measurement for tools/README.md, not a test (no target).
// Usage: node frame_time.js CHROMIUM PAGE.html [SECONDS]
'use strict';
const path = require('path');
const {Browser} = require('./cdp_pipe.js');

(async () => {
  const [chromium, page, seconds = '5'] = process.argv.slice(2);
  const browser = new Browser(chromium, {timeoutMs: 120000});
  try {
    const tab = await browser.newPage(1280, 720);
    const started = Date.now();
    await tab.goto('file://' + path.resolve(page) + '#paused');
    console.log(`loaded in ${Date.now() - started} ms`);
    await tab.evaluate('phiqViewer.play()');
    await tab.evaluate(`new Promise((r) => setTimeout(r, ${1000 * +seconds}))`);
    const t = await tab.evaluate('phiqViewer.pause(), phiqViewer.timing()');
    const f = (s) => `mean ${s.mean.toFixed(1)}, median ${s.median.toFixed(1)}, 95th percentile ${s.p95.toFixed(1)}, max ${s.max.toFixed(1)} (${s.count} frames)`;
    console.log(`frame interval (ms): ${f(t.frameInterval)}`);
    console.log(`draw (ms): ${f(t.draw)}`);
    if (tab.errors.length) console.log('console errors: ' + tab.errors.join('; '));
  } finally {
    await browser.close();
  }
})();
