// The review page's viewers: each failing pass's golden and actual at full resolution, decoded
// from the zlib-compressed pixel data that report/mod.rs embeds (exact values: 8-bit, fp16 or
// fp32), shown side by side, as a swipe or as a flicker, zoomable, with an exposure control for
// float passes, a false-colour difference scaled to the pass's tolerance, and a pixel inspector
// that prints the stored values. `window.reviewReady` resolves when every viewer is drawn.
'use strict';
(function () {
  async function inflate(id) {
    const text = document.getElementById('blob-' + id).textContent.trim();
    const binary = atob(text);
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  function halfToFloat(h) {
    const sign = h & 0x8000 ? -1 : 1;
    const exponent = (h >> 10) & 0x1f;
    const fraction = h & 0x3ff;
    if (exponent === 0) return sign * Math.pow(2, -14) * (fraction / 1024);
    if (exponent === 31) return fraction ? NaN : sign * Infinity;
    return sign * Math.pow(2, exponent - 15) * (1 + fraction / 1024);
  }

  // Values in the image's own units: 0..255 for 8-bit images, floats otherwise.
  function decode(bytes, kind) {
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    if (kind === 'u8') return bytes;
    if (kind === 'f16') {
      const out = new Float32Array(bytes.length / 2);
      for (let i = 0; i < out.length; i++) out[i] = halfToFloat(view.getUint16(2 * i, true));
      return out;
    }
    const out = new Float32Array(bytes.length / 4);
    for (let i = 0; i < out.length; i++) out[i] = view.getFloat32(4 * i, true);
    return out;
  }

  function srgb(x) {
    return x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055;
  }

  // False colour of an error in units of the threshold: black for none, dark blue to cyan below
  // the threshold, yellow to red from 1x to 4x, magenta beyond.
  function falseColour(t) {
    if (!(t > 0)) return t === 0 ? [0, 0, 0] : [255, 0, 255];
    if (t < 1) return [0, Math.round(204 * t), Math.round(90 + 165 * t)];
    if (t < 4) return [255, Math.round(255 * (1 - (t - 1) / 3)), 0];
    return [255, 0, 255];
  }

  function format(value, kind) {
    if (kind === 'u8') return String(value);
    return Number.isFinite(value) ? String(Number(value.toPrecision(6))) : String(value);
  }

  function element(tag, attributes, text) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attributes || {})) e.setAttribute(k, v);
    if (text !== undefined) e.textContent = text;
    return e;
  }

  class Viewer {
    constructor(root) {
      const d = root.dataset;
      this.root = root;
      this.width = Number(d.width);
      this.height = Number(d.height);
      this.channels = Number(d.channels);
      this.kind = d.kind;
      this.display = d.display;
      this.threshold = Number(d.threshold);
      this.floor = d.floor === '' ? null : Number(d.floor);
      this.counted = d.rgb === '1' ? Math.min(3, this.channels) : this.channels;
      this.exposure = 0;
    }

    async load() {
      const [golden, actual] = await Promise.all([
        inflate(this.root.dataset.golden),
        inflate(this.root.dataset.actual),
      ]);
      this.golden = decode(golden, this.kind);
      this.actual = decode(actual, this.kind);
      if (this.display === 'depth') {
        let lo = Infinity, hi = -Infinity;
        for (const v of this.golden) if (Number.isFinite(v) && v < 1) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
        this.depthRange = [lo, Math.max(hi - lo, 1e-9)];
      }
      this.build();
      this.drawDiff();
      this.draw();
    }

    // One channel value as a display byte, after exposure.
    toByte(v) {
      let x;
      switch (this.display) {
        case 'srgb8': return v;
        case 'hdr': x = srgb(Math.min(Math.max(v * Math.pow(2, this.exposure), 0), 1)); break;
        case 'signed': x = (v * 0.5 + 0.5) * Math.pow(2, this.exposure); break;
        case 'depth': x = v >= 1 ? 1 : (v - this.depthRange[0]) / this.depthRange[1]; break;
        default: x = v * Math.pow(2, this.exposure);
      }
      return Math.round(Math.min(Math.max(x, 0), 1) * 255);
    }

    // The pixel's error in units of the threshold, as the tolerance measures it.
    error(pixel) {
      const scale = this.kind === 'u8' ? 1 / 255 : 1;
      let worst = 0;
      for (let c = 0; c < this.counted; c++) {
        const i = pixel * this.channels + c;
        const a = this.actual[i] * scale, g = this.golden[i] * scale;
        let e = Math.abs(a - g);
        if (this.floor !== null) e /= Math.max(Math.abs(g), this.floor);
        if (!Number.isFinite(e)) return NaN;
        worst = Math.max(worst, e);
      }
      return worst / this.threshold;
    }

    // The display image of `data` at the current exposure, put into each of `canvases`.
    paint(canvases, data) {
      const image = new ImageData(this.width, this.height);
      const n = this.width * this.height;
      for (let p = 0; p < n; p++) {
        for (let c = 0; c < 3; c++) {
          const source = this.channels === 1 ? 0 : c;
          image.data[4 * p + c] = this.toByte(data[p * this.channels + source]);
        }
        image.data[4 * p + 3] = 255;
      }
      for (const canvas of canvases) canvas.getContext('2d').putImageData(image, 0, 0);
    }

    // Golden and actual, redrawn when the exposure changes.
    draw() {
      this.paint(this.canvases.golden, this.golden);
      this.paint(this.canvases.actual, this.actual);
    }

    // The false-colour difference, which the exposure does not change: drawn once.
    drawDiff() {
      const diff = new ImageData(this.width, this.height);
      const n = this.width * this.height;
      for (let p = 0; p < n; p++) {
        const [r, g, b] = falseColour(this.error(p));
        diff.data.set([r, g, b, 255], 4 * p);
      }
      this.canvases.diff.getContext('2d').putImageData(diff, 0, 0);
    }

    canvas(role) {
      const c = element('canvas', { class: role, width: this.width, height: this.height });
      c.addEventListener('mousemove', (e) => this.inspect(e, c));
      return c;
    }

    build() {
      const label = this.root.dataset.label;
      const bar = element('div', { class: 'toolbar' });
      const modes = element('span', { class: 'modes' });
      for (const [mode, text] of [['side', 'side by side'], ['swipe', 'swipe'], ['flicker', 'flicker']]) {
        const b = element('button', { type: 'button', 'data-mode': mode }, text);
        b.addEventListener('click', () => this.setMode(mode));
        modes.append(b);
      }
      bar.append(modes);
      const zoom = element('select', { class: 'zoom', 'aria-label': 'zoom' });
      for (const z of [1, 2, 4, 8, 16]) zoom.append(element('option', { value: z }, z + '\u00d7'));
      zoom.addEventListener('change', () => this.setZoom(Number(zoom.value)));
      const zoomLabel = element('label', {}, 'zoom ');
      zoomLabel.append(zoom);
      bar.append(zoomLabel);
      if (this.kind !== 'u8' && this.display !== 'depth') {
        const exposure = element('input', { type: 'range', class: 'exposure', min: -10, max: 10, step: 0.5, value: 0 });
        const ev = element('output', { class: 'ev' }, '0 EV');
        exposure.addEventListener('input', () => {
          this.exposure = Number(exposure.value);
          ev.textContent = this.exposure + ' EV';
          this.draw();
        });
        const l = element('label', {}, 'exposure ');
        l.append(exposure, ev);
        bar.append(l);
      }
      const legend = element('span', { class: 'legend' });
      const t = this.threshold;
      const unit = this.floor === null ? '' : ' (relative, floor ' + this.floor + ')';
      legend.append(element('span', {}, 'difference: 0'), element('span', { class: 'bar' }),
        element('span', {}, '\u22654\u00d7 threshold ' + Number(t.toPrecision(6)) + unit +
          '; cyan just under it, yellow just over'));
      bar.append(legend);

      const golden = this.canvas('golden'), actual = this.canvas('actual'), diff = this.canvas('diff');
      const figure = (content, caption, cls) => {
        const f = element('figure', { class: cls });
        f.append(content, element('figcaption', {}, caption));
        return f;
      };
      // Swipe: the golden under the actual, whose left part the slider uncovers.
      const swipeGolden = this.canvas('golden'), swipeActual = this.canvas('actual');
      const swipeStack = element('div', { class: 'stack' });
      swipeStack.append(swipeGolden, swipeActual);
      const slider = element('input', { type: 'range', class: 'swipe-slider', min: 0, max: 100, value: 50, 'aria-label': 'swipe' });
      slider.addEventListener('input', () => this.setSwipe(Number(slider.value)));
      const swipe = element('figure', { class: 'swipe' });
      swipe.append(swipeStack, slider, element('figcaption', {}, 'left: golden, right: actual (' + label + ')'));
      // Flicker: golden and actual in one place, alternated by a button or automatically.
      const flickerGolden = this.canvas('golden'), flickerActual = this.canvas('actual');
      const flickerStack = element('div', { class: 'stack' });
      flickerStack.append(flickerGolden, flickerActual);
      const showing = element('button', { type: 'button', class: 'flip' }, 'showing: actual (click or press to flip)');
      showing.addEventListener('click', () => this.flip());
      const auto = element('input', { type: 'checkbox', class: 'auto-flicker' });
      auto.addEventListener('change', () => {
        clearInterval(this.timer);
        if (auto.checked) this.timer = setInterval(() => this.flip(), 500);
      });
      const autoLabel = element('label', {}, ' every 0.5 s');
      autoLabel.prepend(auto);
      const flicker = element('figure', { class: 'flicker' });
      flicker.append(flickerStack, showing, autoLabel);

      const panes = element('div', { class: 'panes' });
      panes.append(figure(golden, 'golden', 'side'), figure(actual, 'actual (' + label + ')', 'side'),
        figure(diff, 'difference, in units of the threshold', 'side'), swipe, flicker);
      this.inspector = element('output', { class: 'inspector' }, 'move the pointer over an image to read its pixels');
      this.root.append(bar, panes, this.inspector);
      this.canvases = {
        golden: [golden, swipeGolden, flickerGolden],
        actual: [actual, swipeActual, flickerActual],
        diff,
        all: [golden, actual, diff, swipeGolden, swipeActual, flickerGolden, flickerActual],
      };
      this.flickerActual = flickerActual;
      this.swipeActual = swipeActual;
      this.flipButton = showing;
      this.setMode('side');
      this.setSwipe(50);
    }

    setMode(mode) {
      this.root.classList.remove('mode-side', 'mode-swipe', 'mode-flicker');
      this.root.classList.add('mode-' + mode);
      for (const b of this.root.querySelectorAll('.modes button')) b.classList.toggle('on', b.dataset.mode === mode);
    }

    setZoom(zoom) {
      for (const c of this.canvases.all) {
        c.style.width = this.width * zoom + 'px';
        c.style.height = this.height * zoom + 'px';
      }
    }

    setSwipe(percent) {
      this.swipeActual.style.clipPath = 'inset(0 0 0 ' + percent + '%)';
    }

    flip() {
      const hidden = this.flickerActual.style.visibility === 'hidden';
      this.flickerActual.style.visibility = hidden ? 'visible' : 'hidden';
      this.flipButton.textContent = 'showing: ' + (hidden ? 'actual' : 'golden') + ' (click or press to flip)';
    }

    inspect(event, canvas) {
      // The pixel under the pointer: inside the canvas's border, scaled by the zoom.
      const rect = canvas.getBoundingClientRect();
      const x = Math.floor((event.clientX - rect.left - canvas.clientLeft) * this.width / canvas.clientWidth);
      const y = Math.floor((event.clientY - rect.top - canvas.clientTop) * this.height / canvas.clientHeight);
      if (x < 0 || y < 0 || x >= this.width || y >= this.height) return;
      const p = y * this.width + x;
      const values = (data) => Array.from({ length: this.channels }, (_, c) => format(data[p * this.channels + c], this.kind)).join(' ');
      const e = this.error(p);
      this.inspector.textContent = 'pixel (' + x + ', ' + y + ')  golden: ' + values(this.golden) +
        '  actual: ' + values(this.actual) + '  error: ' + (Number.isFinite(e) ? Number(e.toPrecision(3)) : e) + '\u00d7 threshold';
    }
  }

  const filter = document.getElementById('failures-only');
  if (filter) {
    const apply = () => document.body.classList.toggle('failures-only', filter.checked);
    filter.addEventListener('change', apply);
    apply();
  }
  for (const button of document.querySelectorAll('button.copy')) {
    button.addEventListener('click', async () => {
      try {
        await navigator.clipboard.writeText(button.dataset.copy);
        button.textContent = 'copied';
      } catch (_) {
        const code = button.previousElementSibling;
        window.getSelection().selectAllChildren(code);
        button.textContent = 'selected; press Ctrl+C';
      }
    });
  }
  const viewers = Array.from(document.querySelectorAll('.viewer'), (root) => new Viewer(root));
  window.reviewReady = Promise.all(viewers.map((v) => v.load().catch((e) => {
    v.root.append(element('p', { class: 'failed' }, 'cannot show this pass: ' + e));
    throw e;
  })));
})();
