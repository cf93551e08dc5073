// A headless Chromium driven over the DevTools protocol on a pipe (--remote-debugging-pipe: JSON messages ended
// by a NUL byte on file descriptors 3 and 4), with nothing but node: no npm package, no port, no download. Enough
// for the viewer's tests: open a page, evaluate scripts, collect console errors, take screenshots.
'use strict';
const {spawn} = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');

// The flags of a quiet, reproducible browser: no network, no sync, a fresh profile, software WebGL (SwiftShader).
function flags(profile, width, height) {
  return ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
          '--disable-background-networking', '--disable-component-update', '--disable-sync',
          '--use-angle=swiftshader', '--use-gl=angle', '--enable-unsafe-swiftshader', '--hide-scrollbars',
          '--force-device-scale-factor=1', '--font-render-hinting=none', `--window-size=${width},${height}`,
          `--user-data-dir=${profile}`, '--remote-debugging-pipe', 'about:blank'];
}

class Browser {
  // Starts `exe`; `timeoutMs` bounds every command (a hung browser fails the test rather than stalling it).
  constructor(exe, {width = 1280, height = 720, timeoutMs = 20000} = {}) {
    this.profile = fs.mkdtempSync(path.join(os.tmpdir(), 'phiq-chromium-'));
    this.proc = spawn(exe, flags(this.profile, width, height), {stdio: ['ignore', 'ignore', 'pipe', 'pipe', 'pipe']});
    this.stderr = '';
    this.proc.stderr.on('data', (b) => { this.stderr += b; });
    this.out = this.proc.stdio[3];
    this.timeoutMs = timeoutMs;
    this.next = 1;
    this.pending = new Map();
    this.listeners = [];
    let buffer = Buffer.alloc(0);
    this.proc.stdio[4].on('data', (chunk) => {
      buffer = Buffer.concat([buffer, chunk]);
      for (let end = buffer.indexOf(0); end >= 0; end = buffer.indexOf(0)) {
        const msg = JSON.parse(buffer.subarray(0, end).toString('utf8'));
        buffer = buffer.subarray(end + 1);
        if (msg.id && this.pending.has(msg.id)) {
          const {resolve, reject, timer, method} = this.pending.get(msg.id);
          clearTimeout(timer);
          this.pending.delete(msg.id);
          if (msg.error) reject(new Error(`${method}: ${msg.error.message}`));
          else resolve(msg.result);
        } else if (msg.method) {
          for (const l of this.listeners) l(msg);
        }
      }
    });
    this.exited = new Promise((resolve) => this.proc.on('exit', resolve));
  }

  // One protocol command (on the page's session when sessionId is given).
  send(method, params = {}, sessionId) {
    const id = this.next++;
    return new Promise((resolve, reject) => {
      const timer = setTimeout(() => {
        this.pending.delete(id);
        reject(new Error(`${method}: no answer in ${this.timeoutMs} ms`));
      }, this.timeoutMs);
      this.pending.set(id, {resolve, reject, timer, method});
      this.out.write(JSON.stringify({id, method, params, ...(sessionId ? {sessionId} : {})}) + '\0');
    });
  }

  on(listener) { this.listeners.push(listener); }

  // A new tab of the given size, its events listened to: returns a Page.
  async newPage(width, height) {
    const {targetId} = await this.send('Target.createTarget', {url: 'about:blank'});
    const {sessionId} = await this.send('Target.attachToTarget', {targetId, flatten: true});
    const page = new Page(this, sessionId);
    for (const domain of ['Page', 'Runtime', 'Log']) await page.send(`${domain}.enable`);
    await page.send('Emulation.setDeviceMetricsOverride', {width, height, deviceScaleFactor: 1, mobile: false});
    return page;
  }

  async close() {
    try {
      await this.send('Browser.close');
    } catch (e) {
      this.proc.kill();
    }
    await this.exited;
    fs.rmSync(this.profile, {recursive: true, force: true});
  }
}

class Page {
  constructor(browser, sessionId) {
    this.browser = browser;
    this.sessionId = sessionId;
    this.errors = [];  // console errors and uncaught exceptions, as text
    this.loaded = null;
    browser.on((msg) => {
      if (msg.sessionId !== sessionId) return;
      const p = msg.params;
      if (msg.method === 'Runtime.consoleAPICalled' && (p.type === 'error' || p.type === 'assert'))
        this.errors.push('console.' + p.type + ': ' + p.args.map((a) => a.value ?? a.description).join(' '));
      else if (msg.method === 'Runtime.exceptionThrown')
        this.errors.push('exception: ' + (p.exceptionDetails.exception?.description ?? p.exceptionDetails.text));
      else if (msg.method === 'Log.entryAdded' && p.entry.level === 'error')
        this.errors.push('log: ' + p.entry.text + (p.entry.url ? ' (' + p.entry.url + ')' : ''));
      else if (msg.method === 'Page.loadEventFired' && this.loaded) this.loaded();
    });
  }

  send(method, params = {}) { return this.browser.send(method, params, this.sessionId); }

  async goto(url) {
    const loaded = new Promise((resolve) => { this.loaded = resolve; });
    await this.send('Page.navigate', {url});
    await loaded;
  }

  // The value of an expression (awaited if a promise), thrown if it throws.
  async evaluate(expression) {
    const r = await this.send('Runtime.evaluate', {expression, awaitPromise: true, returnByValue: true});
    if (r.exceptionDetails) throw new Error(`${expression}: ${r.exceptionDetails.exception?.description ?? r.exceptionDetails.text}`);
    return r.result.value;
  }

  // A PNG of the page's viewport, or of `clip` ({x, y, width, height} in CSS pixels).
  async screenshot(clip) {
    const params = {format: 'png', captureBeyondViewport: false};
    if (clip) params.clip = {...clip, scale: 1};
    const {data} = await this.send('Page.captureScreenshot', params);
    return Buffer.from(data, 'base64');
  }
}

module.exports = {Browser};
