// grains view: plays a run in the browser with WebGL2. Frames come from
// the server packed (see view.rs: pack_frame) and are drawn as instanced
// disks (2D) or shaded sphere impostors (3D); walls come as polylines.
"use strict";

const state = {
  meta: null, n: 0, index: 0, playing: false, speed: 1, color: "speed",
  cache: new Map(), loading: null, shown: null, lastStep: 0,
  cam2: null, cam3: null, thermo: null,
};
// The hook a browser test reads (and nothing else depends on).
const hook = window.grainsView = {
  ready: false, frame: -1, frames: 0, grains: 0, errors: [],
  litPixels: () => litPixels(),
};

const $ = (id) => document.getElementById(id);
const canvas = $("view");
const gl = canvas.getContext("webgl2", { antialias: true, preserveDrawingBuffer: true });

function fail(msg) {
  hook.errors.push(msg);
  $("status").textContent = msg;
  console.error("grains view: " + msg);
}

// ---- small matrix helpers (column-major, as WebGL wants) ----
function ortho(l, r, b, t, n, f) {
  return [2 / (r - l), 0, 0, 0, 0, 2 / (t - b), 0, 0, 0, 0, -2 / (f - n), 0,
    -(r + l) / (r - l), -(t + b) / (t - b), -(f + n) / (f - n), 1];
}
function perspective(fovy, aspect, n, f) {
  const t = 1 / Math.tan(fovy / 2);
  return [t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (f + n) / (n - f), -1, 0, 0, 2 * f * n / (n - f), 0];
}
function lookAt(eye, at, up) {
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const norm = (a) => { const l = Math.hypot(...a) || 1; return a.map((x) => x / l); };
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const z = norm(sub(eye, at)), x = norm(cross(up, z)), y = cross(z, x);
  return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
}
const IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];

// ---- colours ----
const VIRIDIS = [[68, 1, 84], [72, 36, 117], [65, 68, 135], [53, 95, 141], [42, 120, 142],
  [33, 145, 140], [34, 168, 132], [68, 191, 112], [122, 209, 81], [189, 223, 38], [253, 231, 37]];
function viridis(t, out, k) {
  t = Math.min(Math.max(Number.isFinite(t) ? t : 0, 0), 1) * 10;
  const i = Math.min(Math.floor(t), 9), f = t - i, a = VIRIDIS[i], b = VIRIDIS[i + 1];
  for (let c = 0; c < 3; c++) out[k + c] = (a[c] + (b[c] - a[c]) * f) / 255;
}
const KINDS = [[31, 119, 180], [255, 127, 14], [44, 160, 44], [214, 39, 40],
  [148, 103, 189], [140, 86, 75], [227, 119, 194], [127, 127, 127]];
function hue(id, out, k) {
  // Golden-ratio hue steps keep neighbouring ids apart.
  const h = (Math.imul(id, 2654435761) >>> 0) / 4294967296;
  for (let c = 0; c < 3; c++) {
    const x = Math.abs(((h + c / 3) % 1) * 6 - 3) - 1;
    out[k + c] = (40 + 170 * Math.min(Math.max(x, 0), 1)) / 255;
  }
}

// ---- GL programs ----
function program(vs, fs) {
  const make = (type, src) => {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  };
  const p = gl.createProgram();
  gl.attachShader(p, make(gl.VERTEX_SHADER, vs));
  gl.attachShader(p, make(gl.FRAGMENT_SHADER, fs));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}
let grainProg, lineProg, quad, grainVao, ballVao, lineVao, buffers = {};

function setupGl() {
  grainProg = program(`#version 300 es
layout(location=0) in vec2 corner;
layout(location=1) in vec3 center;
layout(location=2) in float radius;
layout(location=3) in vec3 color;
uniform mat4 uView, uProj;
out vec2 vUv; out vec3 vColor;
void main() {
  vec4 p = uView * vec4(center, 1.0);
  p.xy += corner * radius;
  gl_Position = uProj * p;
  vUv = corner; vColor = color;
}`, `#version 300 es
precision mediump float;
in vec2 vUv; in vec3 vColor;
uniform int uShade;
out vec4 outColor;
void main() {
  float r2 = dot(vUv, vUv);
  if (r2 > 1.0) discard;
  if (uShade == 1) {
    vec3 n = vec3(vUv, sqrt(1.0 - r2));
    float l = 0.35 + 0.65 * max(dot(n, normalize(vec3(-0.4, 0.45, 0.8))), 0.0);
    outColor = vec4(vColor * l, 1.0);
  } else {
    outColor = vec4(vColor * (r2 > 0.82 ? 0.6 : 1.0), 1.0);
  }
}`);
  lineProg = program(`#version 300 es
layout(location=0) in vec3 pos;
uniform mat4 uView, uProj;
void main() { gl_Position = uProj * uView * vec4(pos, 1.0); }`, `#version 300 es
precision mediump float;
out vec4 outColor;
void main() { outColor = vec4(0.16, 0.16, 0.16, 1.0); }`);
  quad = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, quad);
  gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 1, -1, -1, 1, 1, 1]), gl.STATIC_DRAW);
  const instanced = () => {
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, quad);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 0, 0);
    const bufs = {};
    for (const [loc, size, name] of [[1, 3, "center"], [2, 1, "radius"], [3, 3, "color"]]) {
      bufs[name] = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, bufs[name]);
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, size, gl.FLOAT, false, 0, 0);
      gl.vertexAttribDivisor(loc, 1);
    }
    gl.bindVertexArray(null);
    return [vao, bufs];
  };
  [grainVao, buffers.grain] = instanced();
  [ballVao, buffers.ball] = instanced();
  lineVao = gl.createVertexArray();
  gl.bindVertexArray(lineVao);
  buffers.line = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, buffers.line);
  gl.enableVertexAttribArray(0);
  gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
  gl.bindVertexArray(null);
}

// ---- frames ----
function unpack(buf) {
  const head = new DataView(buf, 0, 24);
  const magic = String.fromCharCode(...new Uint8Array(buf, 0, 4));
  if (magic !== "GRF1") throw new Error("not a packed grains frame");
  const n = head.getUint32(4, true);
  if (buf.byteLength !== 24 + 28 * n) throw new Error(`frame of ${buf.byteLength} bytes for ${n} grains`);
  return {
    n, dim: head.getUint32(8, true), time: head.getFloat64(16, true),
    pos: new Float32Array(buf, 24, 3 * n),
    radius: new Float32Array(buf, 24 + 12 * n, n),
    speed: new Float32Array(buf, 24 + 16 * n, n),
    id: new Uint32Array(buf, 24 + 20 * n, n),
    kind: new Uint32Array(buf, 24 + 24 * n, n),
  };
}

async function fetchChecked(url, how) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: ${r.status} ${await r.text()}`);
  return how(r);
}

function load(i) {
  if (state.cache.has(i)) return state.cache.get(i);
  const p = Promise.all([
    fetchChecked(`/api/frame/${i}`, (r) => r.arrayBuffer()).then(unpack),
    fetchChecked(`/api/walls/${i}`, (r) => r.json()),
  ]).then(([frame, walls]) => ({ frame, walls }));
  state.cache.set(i, p);
  if (state.cache.size > 48) state.cache.delete(state.cache.keys().next().value);
  p.catch(() => state.cache.delete(i));
  return p;
}

function colours(f) {
  const out = new Float32Array(3 * f.n);
  const v = state.meta.dimension === 3 ? 2 : 1;
  if (state.color === "speed" || state.color === "height") {
    let lo = Infinity, hi = -Infinity;
    const val = (i) => (state.color === "speed" ? f.speed[i] : f.pos[3 * i + v]);
    for (let i = 0; i < f.n; i++) { const x = val(i); if (x < lo) lo = x; if (x > hi) hi = x; }
    if (state.color === "speed") lo = 0;
    for (let i = 0; i < f.n; i++) viridis(hi > lo ? (val(i) - lo) / (hi - lo) : 0, out, 3 * i);
    $("legend").style.visibility = "visible";
    const fmt = (x) => (Number.isFinite(x) ? x.toPrecision(3) : "–");
    $("lo").textContent = fmt(lo);
    $("hi").textContent = fmt(hi) + (state.color === "speed" ? " m/s" : " m");
  } else {
    for (let i = 0; i < f.n; i++) {
      if (state.color === "id") hue(f.id[i], out, 3 * i);
      else { const c = KINDS[(f.kind[i] + 7) % 8]; for (let k = 0; k < 3; k++) out[3 * i + k] = c[k] / 255; }
    }
    $("legend").style.visibility = "hidden";
  }
  return out;
}

function upload(shown) {
  const f = shown.frame;
  const g = buffers.grain;
  gl.bindBuffer(gl.ARRAY_BUFFER, g.center); gl.bufferData(gl.ARRAY_BUFFER, f.pos, gl.DYNAMIC_DRAW);
  gl.bindBuffer(gl.ARRAY_BUFFER, g.radius); gl.bufferData(gl.ARRAY_BUFFER, f.radius, gl.DYNAMIC_DRAW);
  gl.bindBuffer(gl.ARRAY_BUFFER, g.color); gl.bufferData(gl.ARRAY_BUFFER, colours(f), gl.DYNAMIC_DRAW);
  const lines = [], balls = [];
  for (const w of shown.walls) {
    if (w.type === "line") {
      for (let k = 0; k + 1 < w.points.length; k++) lines.push(...w.points[k], ...w.points[k + 1]);
    } else if (w.type === "ball") balls.push(w);
  }
  shown.lineCount = lines.length / 3;
  gl.bindBuffer(gl.ARRAY_BUFFER, buffers.line); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(lines), gl.DYNAMIC_DRAW);
  const b = buffers.ball;
  shown.ballCount = balls.length;
  gl.bindBuffer(gl.ARRAY_BUFFER, b.center); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(balls.flatMap((x) => x.center)), gl.DYNAMIC_DRAW);
  gl.bindBuffer(gl.ARRAY_BUFFER, b.radius); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(balls.map((x) => x.radius)), gl.DYNAMIC_DRAW);
  gl.bindBuffer(gl.ARRAY_BUFFER, b.color); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(balls.flatMap(() => [0.55, 0.55, 0.55])), gl.DYNAMIC_DRAW);
}

// ---- cameras ----
function boxOf() {
  const m = state.meta, lo = m.box_lo.slice(), hi = m.box_hi.slice();
  const f = state.shown && state.shown.frame;
  for (let k = 0; k < 3; k++) {
    if (lo[k] === null || hi[k] === null) {
      // No box known: the grains' extent.
      let a = Infinity, b = -Infinity;
      if (f) for (let i = 0; i < f.n; i++) { a = Math.min(a, f.pos[3 * i + k]); b = Math.max(b, f.pos[3 * i + k]); }
      lo[k] = Number.isFinite(a) ? a : 0; hi[k] = Number.isFinite(b) ? b : 1;
    }
  }
  return { lo, hi };
}

function resetCamera() {
  const { lo, hi } = boxOf();
  if (state.meta.dimension === 3) {
    const c = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
    const size = Math.max(...[0, 1, 2].map((k) => hi[k] - lo[k]));
    // Looking along +y with z up, as the pictures do.
    state.cam3 = { target: c, dist: 2.2 * size, yaw: -Math.PI / 2, pitch: 0.25 };
  } else {
    // As the pictures do: up to the highest grain and a margin when the
    // grains fill less than 80% of the box height.
    const f = state.shown.frame;
    let top = -Infinity;
    for (let i = 0; i < f.n; i++) top = Math.max(top, f.pos[3 * i + 1] + f.radius[i]);
    if (Number.isFinite(top)) {
      const cut = top + 0.1 * (top - lo[1]);
      if (cut < lo[1] + 0.8 * (hi[1] - lo[1])) hi[1] = cut;
    }
    const aspect = canvas.width / Math.max(canvas.height, 1);
    state.cam2 = { cx: (lo[0] + hi[0]) / 2, cy: (lo[1] + hi[1]) / 2, half: 0.55 * Math.max(hi[1] - lo[1], (hi[0] - lo[0]) / aspect) };
  }
}

function matrices() {
  const aspect = canvas.width / Math.max(canvas.height, 1);
  if (state.meta.dimension === 3) {
    const c = state.cam3, cp = Math.cos(c.pitch);
    const eye = [c.target[0] + c.dist * cp * Math.cos(c.yaw), c.target[1] + c.dist * cp * Math.sin(c.yaw), c.target[2] + c.dist * Math.sin(c.pitch)];
    return { view: lookAt(eye, c.target, [0, 0, 1]), proj: perspective(0.7, aspect, c.dist / 100, c.dist * 10) };
  }
  const c = state.cam2;
  return { view: IDENTITY, proj: ortho(c.cx - c.half * aspect, c.cx + c.half * aspect, c.cy - c.half, c.cy + c.half, -1e6, 1e6) };
}

// ---- drawing ----
function draw() {
  const w = Math.round(canvas.clientWidth * devicePixelRatio), h = Math.round(canvas.clientHeight * devicePixelRatio);
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.clearColor(1, 1, 1, 1);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  const s = state.shown;
  if (!s) return;
  const three = state.meta.dimension === 3;
  if (three) gl.enable(gl.DEPTH_TEST); else gl.disable(gl.DEPTH_TEST);
  const { view, proj } = matrices();
  gl.useProgram(grainProg);
  gl.uniformMatrix4fv(gl.getUniformLocation(grainProg, "uView"), false, view);
  gl.uniformMatrix4fv(gl.getUniformLocation(grainProg, "uProj"), false, proj);
  gl.uniform1i(gl.getUniformLocation(grainProg, "uShade"), three ? 1 : 0);
  gl.bindVertexArray(grainVao);
  gl.drawArraysInstanced(gl.TRIANGLE_STRIP, 0, 4, s.frame.n);
  if (s.ballCount) { gl.bindVertexArray(ballVao); gl.drawArraysInstanced(gl.TRIANGLE_STRIP, 0, 4, s.ballCount); }
  gl.useProgram(lineProg);
  gl.uniformMatrix4fv(gl.getUniformLocation(lineProg, "uView"), false, view);
  gl.uniformMatrix4fv(gl.getUniformLocation(lineProg, "uProj"), false, proj);
  gl.bindVertexArray(lineVao);
  gl.drawArrays(gl.LINES, 0, s.lineCount);
  gl.bindVertexArray(null);
  drawThermo();
}

function litPixels() {
  draw();
  const px = new Uint8Array(canvas.width * canvas.height * 4);
  gl.readPixels(0, 0, canvas.width, canvas.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
  let lit = 0;
  for (let k = 0; k < px.length; k += 4) if (px[k] < 250 || px[k + 1] < 250 || px[k + 2] < 250) lit++;
  return lit;
}

function drawThermo() {
  const c = $("thermo"), ctx = c.getContext("2d");
  const w = Math.round(c.clientWidth * devicePixelRatio), h = Math.round(c.clientHeight * devicePixelRatio);
  if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
  ctx.clearRect(0, 0, w, h);
  const t = state.thermo;
  ctx.font = `${12 * devicePixelRatio}px system-ui, sans-serif`;
  ctx.fillStyle = "#555";
  if (!t || t.time.length < 2) { ctx.fillText("no thermo.csv", 10, 20); return; }
  const pad = 40 * devicePixelRatio;
  const t0 = t.time[0], t1 = t.time[t.time.length - 1];
  const e1 = Math.max(...t.energy), e0 = Math.min(0, ...t.energy);
  const X = (x) => pad + (w - 2 * pad) * (x - t0) / ((t1 - t0) || 1);
  const Y = (y) => h - pad / 2 - (h - pad) * (y - e0) / ((e1 - e0) || 1);
  ctx.strokeStyle = "#2a788e"; ctx.lineWidth = 1.5 * devicePixelRatio;
  ctx.beginPath();
  t.time.forEach((x, k) => (k ? ctx.lineTo(X(x), Y(t.energy[k])) : ctx.moveTo(X(x), Y(t.energy[k]))));
  ctx.stroke();
  ctx.fillText(`kinetic energy (J), max ${e1.toPrecision(3)}`, pad, 14 * devicePixelRatio);
  ctx.fillText(`t = ${t0.toPrecision(3)} s`, pad, h - 4);
  ctx.fillText(`${t1.toPrecision(3)} s`, w - pad - 40 * devicePixelRatio, h - 4);
  if (state.shown) {
    const x = X(state.shown.frame.time);
    ctx.strokeStyle = "#c22"; ctx.beginPath(); ctx.moveTo(x, pad / 4); ctx.lineTo(x, h - pad / 2); ctx.stroke();
  }
}

// ---- playing ----
async function show(i) {
  state.index = i;
  try {
    const s = await load(i);
    if (state.index !== i) return;
    state.shown = s;
    upload(s);
    if (!state.cam2 && !state.cam3) resetCamera();
    draw();
    $("slider").value = i;
    $("counter").textContent = `frame ${i + 1} / ${state.n} · t = ${s.frame.time.toPrecision(4)} s · ${s.frame.n} grains`;
    hook.frame = i; hook.grains = s.frame.n; hook.ready = true;
  } catch (e) {
    state.playing = false;
    $("play").textContent = "Play";
    fail(`frame ${i}: ${e.message}`);
  }
}

function tick(now) {
  if (state.playing && state.shown && now - state.lastStep >= 100 / state.speed && state.index === hook.frame) {
    state.lastStep = now;
    const next = (state.index + 1) % state.n;
    load((next + 1) % state.n).catch(() => {}); // read ahead
    show(next);
  }
  requestAnimationFrame(tick);
}

function controls() {
  $("play").onclick = () => {
    state.playing = !state.playing;
    $("play").textContent = state.playing ? "Pause" : "Play";
  };
  $("slider").oninput = (e) => show(Number(e.target.value));
  $("speed").onchange = (e) => { state.speed = Number(e.target.value); };
  $("color").onchange = (e) => { state.color = e.target.value; if (state.shown) { upload(state.shown); draw(); } };
  let drag = null;
  canvas.addEventListener("pointerdown", (e) => { drag = { x: e.clientX, y: e.clientY }; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener("pointerup", () => { drag = null; });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag || !state.shown) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag = { x: e.clientX, y: e.clientY };
    if (state.cam3) {
      state.cam3.yaw -= dx * 0.01;
      state.cam3.pitch = Math.max(-1.5, Math.min(1.5, state.cam3.pitch + dy * 0.01));
    } else if (state.cam2) {
      const k = 2 * state.cam2.half / canvas.clientHeight;
      state.cam2.cx -= dx * k; state.cam2.cy += dy * k;
    }
    draw();
  });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    const f = Math.exp(e.deltaY * 0.001);
    if (state.cam3) state.cam3.dist *= f; else if (state.cam2) state.cam2.half *= f;
    draw();
  }, { passive: false });
  canvas.addEventListener("dblclick", () => { resetCamera(); draw(); });
  window.addEventListener("resize", draw);
}

async function main() {
  if (!gl) { fail("this browser has no WebGL2"); return; }
  setupGl();
  controls();
  try {
    state.meta = await fetchChecked("/api/meta", (r) => r.json());
  } catch (e) { fail(e.message); return; }
  state.n = state.meta.times.length;
  hook.frames = state.n;
  $("run").textContent = `${state.meta.run} (${state.meta.dimension}D)`;
  $("hint").textContent = state.meta.dimension === 3 ? "drag: orbit · wheel: zoom · double-click: reset" : "drag: pan · wheel: zoom · double-click: reset";
  $("slider").max = state.n - 1;
  fetch("/api/thermo").then((r) => (r.ok ? r.text() : "")).then((text) => {
    const rows = text.trim().split("\n");
    if (rows.length < 2) return;
    const head = rows[0].split(","), it = head.indexOf("time"), ie = head.indexOf("kinetic_energy");
    if (it < 0 || ie < 0) return;
    const cols = rows.slice(1).map((l) => l.split(",").map(Number));
    state.thermo = { time: cols.map((c) => c[it]), energy: cols.map((c) => c[ie]) };
    drawThermo();
  }).catch(() => {});
  await show(0);
  requestAnimationFrame(tick);
}

main();
