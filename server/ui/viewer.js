// Radiant's viewer (served by radiantd at /ui/; docs/API.md, "Sessions"). Plain JavaScript, no
// third-party code, same origin only. It opens a progressive session, reads its Server-Sent Events over
// fetch (EventSource cannot send the bearer token, which stays in this page's memory), draws each new
// frame, and turns mouse and form input into merge patches of the session's request.
'use strict';

const QUALITIES = ['', 'draft', 'preview', 'final', 'reference'];
const $ = (id) => document.getElementById(id);

// Everything the page knows; tests read it through window.radiantViewer.
const state = {
  token: '',
  info: null,
  session: null,      // {id, ...} as POST /v1/sessions answered
  size: 256,
  orbit: null,        // {theta_deg, phi_deg, radius} once the first frame told the camera
  target: null,       // [x, y, z]
  generation: -1,
  frames: [],         // the current generation's frame events
  lastFrame: null,    // the last frame event drawn
  drawn: null,        // {generation, batches} of the image on the canvas
  events: [],         // every event received: {id, event, generation}
  changeSentAt: {},   // generation -> performance.now() of the change that made it (camera or form)
  firstFrameMs: [],   // per camera change: ms from sending the change to its first frame on screen
  done: null,         // the last done event
  errors: [],
  ended: null,
};

function headers(extra) {
  const h = Object.assign({}, extra || {});
  if (state.token) h.Authorization = 'Bearer ' + state.token;
  return h;
}

function setStatus(text, isError) {
  const s = $('status');
  s.textContent = text;
  s.classList.toggle('error', !!isError);
}

async function call(method, path, body, contentType) {
  const init = { method, headers: headers() };
  if (body !== undefined) {
    init.headers['Content-Type'] = contentType || 'application/json';
    init.body = (body instanceof ArrayBuffer) ? body : JSON.stringify(body);
  }
  const r = await fetch(path, init);
  const text = await r.text();
  let json = null;
  try { json = text ? JSON.parse(text) : null; } catch (e) { json = null; }
  if (!r.ok) {
    const detail = json && json.detail ? json.detail : text;
    const where = json && json.pointer ? ' (at ' + json.pointer + ')' : '';
    const err = new Error(r.status + ': ' + detail + where);
    err.status = r.status;
    err.problem = json;
    throw err;
  }
  return json;
}

// ---- the session and its events --------------------------------------------------------------

let abortEvents = null;

async function openSession(scene) {
  if (state.session) await endSession();
  state.size = Number($('size').value);
  for (const c of ['frame', 'reference', 'error']) { $(c).width = state.size; $(c).height = state.size; }
  Object.assign(state, { orbit: null, target: null, generation: -1, frames: [], lastFrame: null, drawn: null,
    done: null, ended: null });
  const request = Object.assign({ scene, width: state.size, height: state.size }, stripNulls(formRequest()));
  setStatus('opening a session…');
  const sent = performance.now();
  state.session = await call('POST', '/v1/sessions', request);
  state.changeSentAt = { 0: sent };
  state.firstFrameMs = [];
  setStatus('session ' + state.session.id);
  listen(state.session.id);
}

async function endSession() {
  const s = state.session;
  state.session = null;
  if (abortEvents) abortEvents.abort();
  if (s) { try { await call('DELETE', '/v1/sessions/' + s.id); } catch (e) { /* already ended */ } }
}

// Reads the session's event stream; when the connection drops while the session is still this page's
// (a proxy's timeout, a network change), it connects again a second later: the new stream starts with
// the session's state, so nothing is lost but skipped frames.
async function listen(id) {
  const ctrl = new AbortController();
  abortEvents = ctrl;
  try {
    const r = await fetch('/v1/sessions/' + id + '/events', { headers: headers(), signal: ctrl.signal });
    if (!r.ok) { setStatus('events: HTTP ' + r.status, true); return; }
    const reader = r.body.getReader();
    const decoder = new TextDecoder();
    let buffer = '';
    for (;;) {
      const chunk = await reader.read();
      if (chunk.done) break;
      buffer += decoder.decode(chunk.value, { stream: true });
      let end;
      while ((end = buffer.indexOf('\n\n')) >= 0) {
        const block = buffer.slice(0, end);
        buffer = buffer.slice(end + 2);
        parseEvent(block);
      }
    }
  } catch (e) { /* aborted, or the connection broke */ }
  if (!ctrl.signal.aborted && !state.ended && state.session && state.session.id === id)
    setTimeout(() => { if (state.session && state.session.id === id && !state.ended) listen(id); }, 1000);
}

function parseEvent(block) {
  let event = 'message', data = '', id = null;
  for (const line of block.split('\n')) {
    if (line.startsWith(':')) continue;  // a keep-alive comment
    const colon = line.indexOf(':');
    const field = colon < 0 ? line : line.slice(0, colon);
    let value = colon < 0 ? '' : line.slice(colon + 1);
    if (value.startsWith(' ')) value = value.slice(1);
    if (field === 'event') event = value;
    else if (field === 'data') data += (data ? '\n' : '') + value;
    else if (field === 'id') id = Number(value);
  }
  if (!data) return;
  onEvent(event, JSON.parse(data), id);
}

function onEvent(event, data, id) {
  state.events.push({ id, event, generation: data.generation });
  if (event === 'generation') {
    state.generation = data.generation;
    state.frames = [];
    state.done = null;
  } else if (event === 'frame') {
    if (data.generation !== state.generation) return;
    state.frames.push(data);
    showFrame(data);
  } else if (event === 'done') {
    state.done = data;
    setStatus('converged: ' + data.batches + ' batches (' + data.stopped_by + ')');
  } else if (event === 'error') {
    state.errors.push(data);
    setStatus((data.error && data.error.detail) || 'the render failed', true);
  } else if (event === 'ended') {
    state.ended = data.reason;
    setStatus('session ended (' + data.reason + ')', data.reason !== 'deleted');
  }
}

// Frames are fetched one at a time; while one loads, only the newest event waits (the others are stale).
let fetching = false, pendingFrame = null;

async function showFrame(frame) {
  if (fetching) { pendingFrame = frame; return; }
  fetching = true;
  try {
    const r = await fetch(frame.url, { headers: headers() });
    if (r.ok) {
      const generation = Number(r.headers.get('X-Radiant-Generation'));
      const batches = Number(r.headers.get('X-Radiant-Batches'));
      const bitmap = await createImageBitmap(await r.blob());
      const canvas = $('frame');
      const ctx = canvas.getContext('2d');
      ctx.imageSmoothingEnabled = false;
      ctx.drawImage(bitmap, 0, 0, canvas.width, canvas.height);
      state.drawn = { generation, batches, width: bitmap.width, height: bitmap.height };
      state.lastFrame = frame;
      const sent = state.changeSentAt[generation];
      if (sent !== undefined && batches >= 1 && !state.firstFrameMs.some((f) => f.generation === generation)) {
        state.firstFrameMs.push({ generation, width: bitmap.width, ms: performance.now() - sent });
      }
      learnCamera(frame.stats && frame.stats.camera);
      readout(frame);
      drawBars(frame.stats && frame.stats.passes);
      drawCurve();
      if ($('compare').checked) drawReference(frame);
    }
  } finally {
    fetching = false;
  }
  if (pendingFrame) { const next = pendingFrame; pendingFrame = null; showFrame(next); }
}

// The first frame says where the scene camera is: the orbit starts there.
function learnCamera(camera) {
  if (state.orbit || !camera || !camera.position || !camera.target) return;
  const d = [0, 1, 2].map((i) => camera.position[i] - camera.target[i]);
  const r = Math.hypot(d[0], d[1], d[2]) || 1;
  state.target = camera.target.slice();
  state.orbit = {
    theta_deg: Math.atan2(d[0], d[2]) * 180 / Math.PI,
    phi_deg: Math.acos(Math.max(-1, Math.min(1, d[1] / r))) * 180 / Math.PI,
    radius: r,
  };
}

function readout(frame) {
  const c = (frame.stats && frame.stats.camera) || {};
  const fmt = (v) => (v === null || v === undefined) ? '–' : Number(v).toPrecision(3);
  const last = state.firstFrameMs[state.firstFrameMs.length - 1];
  $('readout').textContent =
    'generation ' + frame.generation + ' · batch ' + frame.batches + ' · ' + fmt(frame.elapsed_ms) + ' ms' +
    ' · estimated RMSE ' + fmt(frame.estimated_rmse) + ' (' + frame.estimate_kind + ')' +
    (frame.metrics ? ' · RMSE vs reference ' + fmt(frame.metrics.rmse) : '') + '\n' +
    'camera ' + JSON.stringify(c.position || []) + ' → ' + JSON.stringify(c.target || []) +
    (last ? ' · change → first frame ' + last.ms.toFixed(0) + ' ms' : '');
}

function drawBars(passes) {
  const bars = $('bars');
  bars.textContent = '';
  if (!passes) return;
  const max = Math.max(1e-3, ...passes.map((p) => Math.max(p.gpu_ms || 0, p.cpu_ms || 0)));
  for (const p of passes) {
    const row = document.createElement('div');
    row.className = 'bar';
    const name = document.createElement('span');
    name.className = 'name';
    name.textContent = p.name;
    row.appendChild(name);
    for (const kind of ['gpu', 'cpu']) {
      const b = document.createElement('div');
      b.className = kind;
      b.style.width = Math.round(100 * (p[kind + '_ms'] || 0) / max) + 'px';
      b.title = kind.toUpperCase() + ' ' + (p[kind + '_ms'] || 0).toFixed(2) + ' ms';
      row.appendChild(b);
    }
    const t = document.createElement('span');
    t.textContent = (p.gpu_ms || 0).toFixed(1) + ' / ' + (p.cpu_ms || 0).toFixed(1);
    row.appendChild(t);
    bars.appendChild(row);
  }
}

// Error against time for this generation: the true RMSE when scored against the reference, else the
// batches' estimate (noise only).
function drawCurve() {
  const svg = $('curve');
  svg.textContent = '';
  const pts = state.frames.map((f) => [f.elapsed_ms, f.metrics ? f.metrics.rmse : f.estimated_rmse])
    .filter((p) => typeof p[1] === 'number' && p[1] > 0);
  if (pts.length < 1) return;
  const tMax = Math.max(...pts.map((p) => p[0]), 1);
  const lo = Math.log10(Math.min(...pts.map((p) => p[1]))), hi = Math.log10(Math.max(...pts.map((p) => p[1])));
  const span = Math.max(hi - lo, 0.1);
  const ns = 'http://www.w3.org/2000/svg';
  const line = document.createElementNS(ns, 'polyline');
  line.setAttribute('points', pts.map((p) => (10 + 300 * p[0] / tMax).toFixed(1) + ',' +
    (150 - 130 * (Math.log10(p[1]) - lo) / span).toFixed(1)).join(' '));
  svg.appendChild(line);
  const label = document.createElementNS(ns, 'text');
  label.setAttribute('x', 12);
  label.setAttribute('y', 12);
  label.textContent = 'RMSE ' + Math.pow(10, lo).toPrecision(2) + '…' + Math.pow(10, hi).toPrecision(2) + ', 0…' + tMax.toFixed(0) + ' ms';
  svg.appendChild(label);
}

// The ground truth of the compare block, side by side, and the on-screen difference in false colour.
async function drawReference(frame) {
  if (!state.session) return;
  const r = await fetch('/v1/sessions/' + state.session.id + '/frame?layer=reference', { headers: headers() });
  if (!r.ok) return;
  const bitmap = await createImageBitmap(await r.blob());
  const ref = $('reference').getContext('2d');
  ref.drawImage(bitmap, 0, 0, state.size, state.size);
  const a = $('frame').getContext('2d').getImageData(0, 0, state.size, state.size);
  const b = ref.getImageData(0, 0, state.size, state.size);
  const out = $('error').getContext('2d').createImageData(state.size, state.size);
  for (let i = 0; i < a.data.length; i += 4) {
    const e = (Math.abs(a.data[i] - b.data[i]) + Math.abs(a.data[i + 1] - b.data[i + 1]) + Math.abs(a.data[i + 2] - b.data[i + 2])) / 765;
    const t = Math.min(1, 4 * e);  // 25 % of full scale is red
    out.data[i] = 255 * Math.min(1, 2 * t);
    out.data[i + 1] = 255 * Math.min(1, 2 - 2 * t) * Math.min(1, 2 * t + 0.2);
    out.data[i + 2] = 255 * Math.max(0, 1 - 2 * t);
    out.data[i + 3] = 255;
  }
  $('error').getContext('2d').putImageData(out, 0, 0);
}

// ---- changes: merge patches, one in flight, the newest waiting ----------------------------------

let patching = false, pendingPatch = null;

async function change(patch) {
  if (!state.session) return;
  if (patching) { pendingPatch = Object.assign(pendingPatch || {}, patch); return; }
  patching = true;
  try {
    const sent = performance.now();
    const answer = await call('PATCH', '/v1/sessions/' + state.session.id, patch, 'application/merge-patch+json');
    state.changeSentAt[answer.generation] = sent;
  } catch (e) {
    setStatus(e.message, true);
  } finally {
    patching = false;
  }
  if (pendingPatch) { const next = pendingPatch; pendingPatch = null; change(next); }
}

function cameraPatch(moving) {
  // Moving: a quarter of the resolution and one raster sample per pixel, so that the frame follows the
  // mouse; at rest: full size and the daemon's default supersampling.
  const size = moving ? Math.max(32, state.size >> 2) : state.size;
  return { camera: { orbit: Object.assign({}, state.orbit), target: state.target }, width: size, height: size,
    supersampling: moving ? 1 : null };
}

function setupMouse() {
  const canvas = $('frame');
  let drag = null;
  canvas.addEventListener('pointerdown', (e) => {
    if (!state.orbit) return;
    drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
    canvas.setPointerCapture(e.pointerId);
    canvas.classList.add('dragging');
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX;
    drag.y = e.clientY;
    if (drag.pan) {
      const t = state.orbit.theta_deg * Math.PI / 180, k = state.orbit.radius * 2 / state.size;
      const right = [Math.cos(t), 0, -Math.sin(t)];
      state.target = state.target.map((v, i) => v - k * dx * right[i] + (i === 1 ? k * dy : 0));
    } else {
      state.orbit.theta_deg = ((state.orbit.theta_deg - 0.5 * dx + 540) % 360) - 180;
      state.orbit.phi_deg = Math.max(1, Math.min(179, state.orbit.phi_deg - 0.5 * dy));
    }
    change(cameraPatch(true));
  });
  const release = (e) => {
    if (!drag) return;
    drag = null;
    canvas.classList.remove('dragging');
    change(cameraPatch(false));
  };
  canvas.addEventListener('pointerup', release);
  canvas.addEventListener('pointercancel', release);
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('wheel', (e) => {
    if (!state.orbit) return;
    e.preventDefault();
    state.orbit.radius *= Math.exp(0.001 * e.deltaY);
    change(cameraPatch(false));
  }, { passive: false });
}

// ---- the forms -----------------------------------------------------------------------------------

// The request's configuration as the form sets it (quality and time budget are exclusive).
function formRequest() {
  const q = QUALITIES[Number($('quality').value)];
  const budget = Number($('budget').value);
  return {
    quality: q || null,
    time_budget_ms: q ? null : (budget || null),
    tone_map: $('tonemap').value,
    exposure: Number($('exposure').value),
    compare: $('compare').checked ? { against: 'reference' } : null,
    refine: { max_batches: Number($('batches').value), until_ms: 1000 * Number($('until').value) },
    passes: passesFromForm(),
  };
}

function stripNulls(o) {
  const out = {};
  for (const [k, v] of Object.entries(o)) if (v !== null) out[k] = v;
  return out;
}

// One block per technique, generated from /v1/info (the descriptors' parameters): a state (as the
// planner decides, on, off) and an input per parameter; only what the user set is sent.
function buildPassForm(techniques) {
  const root = $('passes');
  root.textContent = '';
  for (const t of techniques) {
    if (t.available === false) continue;
    const d = document.createElement('details');
    d.dataset.technique = t.name;
    const s = document.createElement('summary');
    s.textContent = t.name;
    s.title = t.summary || t.description || '';
    d.appendChild(s);
    const mode = document.createElement('select');
    mode.className = 'mode';
    for (const [v, label] of [['', 'as planned'], ['on', 'on'], ['off', 'off']]) {
      const o = document.createElement('option');
      o.value = v;
      o.textContent = label;
      mode.appendChild(o);
    }
    d.appendChild(mode);
    for (const [name, p] of Object.entries(t.params || {})) {
      const label = document.createElement('label');
      label.title = p.description || '';
      label.textContent = name + ' ';
      let input;
      if (Array.isArray(p.enum)) {
        input = document.createElement('select');
        for (const v of p.enum) {
          const o = document.createElement('option');
          o.value = JSON.stringify(v);
          o.textContent = String(v);
          if (JSON.stringify(v) === JSON.stringify(p.default)) o.selected = true;
          input.appendChild(o);
        }
      } else if (p.type === 'boolean') {
        input = document.createElement('input');
        input.type = 'checkbox';
        input.checked = !!p.default;
      } else if (p.type === 'number' || p.type === 'integer') {
        input = document.createElement('input');
        input.type = 'number';
        if (p.minimum !== undefined) input.min = p.minimum;
        if (p.maximum !== undefined) input.max = p.maximum;
        input.step = p.type === 'integer' ? 1 : 'any';
        if (p.default !== undefined) input.value = p.default;
      } else {
        continue;  // arrays and objects: through the API
      }
      input.dataset.param = name;
      input.dataset.type = Array.isArray(p.enum) ? 'enum' : p.type;
      input.addEventListener('change', () => { input.dataset.touched = '1'; });
      label.appendChild(input);
      d.appendChild(label);
    }
    root.appendChild(d);
  }
}

function passesFromForm() {
  const passes = {};
  for (const d of $('passes').querySelectorAll('details')) {
    const mode = d.querySelector('.mode').value;
    const params = {};
    for (const input of d.querySelectorAll('[data-param]')) {
      if (!input.dataset.touched) continue;
      const type = input.dataset.type;
      params[input.dataset.param] = type === 'boolean' ? input.checked
        : type === 'enum' ? JSON.parse(input.value) : Number(input.value);
    }
    if (mode === 'off') passes[d.dataset.technique] = false;
    else if (mode === 'on' || Object.keys(params).length) passes[d.dataset.technique] = params;
  }
  return Object.keys(passes).length ? passes : null;
}

function setupForms() {
  $('token').addEventListener('change', () => { state.token = $('token').value; init(); });
  $('open').addEventListener('click', () => openSession({ builtin: $('scene').value }).catch((e) => setStatus(e.message, true)));
  const quality = () => {
    const q = QUALITIES[Number($('quality').value)];
    $('quality-out').textContent = q || 'default';
    if (q) { $('budget').value = 0; $('budget-out').textContent = 'none'; }
  };
  const budget = () => {
    const b = Number($('budget').value);
    $('budget-out').textContent = b ? b + ' ms' : 'none';
    if (b) { $('quality').value = 0; $('quality-out').textContent = 'default'; }
  };
  $('quality').addEventListener('input', quality);
  $('budget').addEventListener('input', budget);
  $('exposure').addEventListener('input', () => { $('exposure-out').textContent = $('exposure').value + ' EV'; });
  for (const id of ['quality', 'budget', 'tonemap', 'exposure', 'compare', 'batches', 'until']) {
    $(id).addEventListener('change', () => {
      const r = formRequest();
      delete r.passes;
      for (const f of ['ref-figure', 'err-figure']) $(f).hidden = !$('compare').checked;
      change(r);
    });
  }
  $('apply').addEventListener('click', () => change({ passes: passesFromForm() }));
  const drop = $('drop');
  drop.addEventListener('dragover', (e) => { e.preventDefault(); drop.classList.add('over'); });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    if (e.dataTransfer.files.length) upload(e.dataTransfer.files);
  });
  $('file').addEventListener('change', () => { if ($('file').files.length) upload($('file').files); });
}

// A .glb as it is; a .gltf with the files it names (chosen or dropped together) packed into one GLB
// here, as `radiant render` packs it (renderer/scene/GltfPackage.h): buffers into the BIN chunk (each
// start 16-byte aligned), external images into bufferViews with their mimeType.
async function upload(files) {
  const list = Array.from(files);
  const main = list.find((f) => /\.(glb|gltf)$/i.test(f.name));
  try {
    if (!main) throw new Error('no .glb or .gltf among ' + list.map((f) => f.name).join(', '));
    setStatus('uploading ' + main.name + '…');
    const binary = /\.glb$/i.test(main.name);
    const packed = binary ? null : await packGltf(main, list);  // null: self-contained, sent as it is
    const answer = packed ? await call('PUT', '/v1/scenes', packed, 'model/gltf-binary')
      : await call('PUT', '/v1/scenes', await main.arrayBuffer(), binary ? 'model/gltf-binary' : 'model/gltf+json');
    await openSession({ digest: answer.digest });
  } catch (e) {
    setStatus((main ? main.name : 'upload') + ': ' + e.message, true);
  }
}

const PNG = [0x89, 0x50, 0x4e, 0x47], JPEG = [0xff, 0xd8, 0xff], WEBP = [0x52, 0x49, 0x46, 0x46];
function mimeOf(bytes) {
  const starts = (sig) => sig.every((b, i) => bytes[i] === b);
  if (starts(PNG)) return 'image/png';
  if (starts(JPEG)) return 'image/jpeg';
  if (starts(WEBP) && String.fromCharCode(...bytes.slice(8, 12)) === 'WEBP') return 'image/webp';
  throw new Error('an image is not PNG, JPEG or WebP');
}

async function packGltf(gltfFile, files) {
  const doc = JSON.parse(await gltfFile.text());
  const byName = new Map(files.map((f) => [f.name, f]));
  const fileFor = async (uri, pointer) => {
    if (/^[a-z][a-z0-9+.-]*:/i.test(uri)) throw new Error(pointer + ': only relative URIs and data: URIs are packed');
    const path = decodeURIComponent(uri);
    if (path.split('/').includes('..')) throw new Error(pointer + ': a ".." segment');
    const f = byName.get(path.split('/').pop());
    if (!f) throw new Error(pointer + ': choose or drop ' + path + ' together with ' + gltfFile.name);
    return new Uint8Array(await f.arrayBuffer());
  };
  const dataUri = (uri) => Uint8Array.from(atob(uri.slice(uri.indexOf(',') + 1)), (c) => c.charCodeAt(0));
  const chunks = [];
  let length = 0;
  const append = (bytes) => {
    const pad = (16 - length % 16) % 16;
    if (pad) { chunks.push(new Uint8Array(pad)); length += pad; }
    const offset = length;
    chunks.push(bytes);
    length += bytes.length;
    return offset;
  };
  const buffers = doc.buffers || [];
  if (buffers.some((b) => b.uri === undefined)) throw new Error('buffers without a uri (EXT_meshopt_compression fallbacks): upload it with `radiant render`');
  if (!buffers.length && !(doc.images || []).some((i) => i.uri && !i.uri.startsWith('data:'))) return null;  // self-contained
  const offsets = [];
  for (const [i, b] of buffers.entries())
    offsets.push(append(b.uri.startsWith('data:') ? dataUri(b.uri) : await fileFor(b.uri, '/buffers/' + i + '/uri')));
  const rebase = (v) => { v.byteOffset = (v.byteOffset || 0) + offsets[v.buffer]; v.buffer = 0; };
  for (const v of doc.bufferViews || []) {
    rebase(v);
    const m = v.extensions && v.extensions.EXT_meshopt_compression;
    if (m) rebase(m);
  }
  doc.bufferViews = doc.bufferViews || [];
  for (const [i, img] of (doc.images || []).entries()) {
    if (!img.uri || img.uri.startsWith('data:')) continue;
    const bytes = await fileFor(img.uri, '/images/' + i + '/uri');
    img.mimeType = mimeOf(bytes);
    img.bufferView = doc.bufferViews.length;
    doc.bufferViews.push({ buffer: 0, byteOffset: append(bytes), byteLength: bytes.length });
    delete img.uri;
  }
  doc.buffers = [{ byteLength: length }];
  // GLB: header, JSON chunk (padded with spaces), BIN chunk (padded with zeros), 4-byte aligned.
  const json = new TextEncoder().encode(JSON.stringify(doc));
  const jsonLength = (json.length + 3) & ~3, binLength = (length + 3) & ~3;
  const total = 12 + 8 + jsonLength + 8 + binLength;
  const out = new Uint8Array(total);
  const view = new DataView(out.buffer);
  view.setUint32(0, 0x46546c67, true);  // "glTF"
  view.setUint32(4, 2, true);
  view.setUint32(8, total, true);
  view.setUint32(12, jsonLength, true);
  view.setUint32(16, 0x4e4f534a, true);  // "JSON"
  out.set(json, 20);
  out.fill(0x20, 20 + json.length, 20 + jsonLength);
  view.setUint32(20 + jsonLength, binLength, true);
  view.setUint32(24 + jsonLength, 0x004e4942, true);  // "BIN\0"
  let at = 28 + jsonLength;
  for (const c of chunks) { out.set(c, at); at += c.length; }
  return out.buffer;
}

async function init() {
  try {
    state.info = await call('GET', '/v1/info');
    const d = state.info.device;
    $('device').textContent = d ? (d.renderer || '') : 'render thread starting';
    const scenes = await call('GET', '/v1/scenes');
    const select = $('scene');
    select.textContent = '';
    for (const b of scenes.builtins) {
      const o = document.createElement('option');
      o.value = o.textContent = b.name;
      select.appendChild(o);
    }
    if ([...select.options].some((o) => o.value === 'cornell_box')) select.value = 'cornell_box';
    buildPassForm(state.info.techniques || []);
    // The sweep reports this daemon serves (radiantd --reports-dir), if any.
    const reports = await fetch('/reports/', { method: 'HEAD', headers: headers() });
    $('reports').hidden = !reports.ok;
    $('no-reports').hidden = reports.ok;
    setStatus('ready: open a scene');
  } catch (e) {
    setStatus(e.status === 401 ? 'this daemon needs its token (above)' : e.message, true);
  }
}

window.addEventListener('pagehide', () => { if (state.session) endSession(); });
window.radiantViewer = { state, openSession, endSession, change, formRequest };
setupMouse();
setupForms();
init();
