// mocap view: the page's player. Reads the JSON block #mocap-view-data (mocap/view/page.py),
// draws it with three.js (global THREE, vendored) and exposes window.mocapView for scripts.
"use strict";
(function () {
  const D = JSON.parse(document.getElementById("mocap-view-data").textContent);
  const $ = (id) => document.getElementById(id);
  const FORCE_SCALE = 0.001;          // metres of arrow per newton (1 m per kN)
  const ARROW_MIN_N = 20;             // arrows of smaller forces are hidden
  const CURVE_COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b",
                         "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];

  function f32(b64) {                  // base64 little-endian float32 -> Float32Array
    const text = atob(b64), bytes = new Uint8Array(text.length);
    for (let i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i);
    return new Float32Array(bytes.buffer);
  }
  const finite = (x, y, z) => x === x && y === y && z === z;   // NaN marks a gap

  // ---- data and time base ---------------------------------------------------------------
  const zUp = D.up === "z";
  const V = zUp ? 2 : 1, H1 = 0, H2 = zUp ? 1 : 2;        // vertical and horizontal axes
  const layers = D.layers.map((l) => Object.assign({}, l, { pts: f32(l.points) }));
  const plates = D.plates.map((p) => Object.assign({}, p, { F: f32(p.force), P: f32(p.point) }));
  const forces = D.forces.map((f) => Object.assign({}, f, { F: f32(f.force), P: f32(f.point) }));
  const tracks = layers.concat(plates, forces);
  const rate = Math.max(1e-9, ...tracks.map((t) => t.rate));
  let duration = Math.max(0, ...tracks.map((t) => (t.frames - 1) / t.rate));
  let curves = null;
  if (D.curves) {
    curves = Object.assign({}, D.curves, { t: f32(D.curves.times), v: f32(D.curves.values) });
    if (!tracks.length) duration = curves.t[curves.samples - 1] || 0;
  }
  const steps = Math.floor(duration * (tracks.length ? rate : 100) + 1e-6) + 1;
  const stepRate = tracks.length ? rate : 100;
  const frameOf = (track, t) => Math.max(0, Math.min(track.frames - 1, Math.round(t * track.rate)));

  // ---- bounds: the box the camera frames and the floor grid covers ----------------------
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const l of layers) {
    const n = l.count * 3, stride = Math.max(1, Math.floor(l.frames / 200));
    for (let f = 0; f < l.frames; f += stride) {
      for (let k = f * n; k < f * n + n; k += 3) {
        const x = l.pts[k], y = l.pts[k + 1], z = l.pts[k + 2];
        if (!finite(x, y, z)) continue;
        lo[0] = Math.min(lo[0], x); lo[1] = Math.min(lo[1], y); lo[2] = Math.min(lo[2], z);
        hi[0] = Math.max(hi[0], x); hi[1] = Math.max(hi[1], y); hi[2] = Math.max(hi[2], z);
      }
    }
  }
  for (const p of plates) {
    for (let k = 0; k < 12; k++) { lo[k % 3] = Math.min(lo[k % 3], p.corners[k]); hi[k % 3] = Math.max(hi[k % 3], p.corners[k]); }
  }
  // how far the layers' centroids travel along each axis: the walk's direction
  const travel = [0, 0, 0];
  for (const l of layers) {
    const n = l.count * 3, stride = Math.max(1, Math.floor(l.frames / 200));
    const cmin = [Infinity, Infinity, Infinity], cmax = [-Infinity, -Infinity, -Infinity];
    for (let f = 0; f < l.frames; f += stride) {
      const s = [0, 0, 0];
      let count = 0;
      for (let k = f * n; k < f * n + n; k += 3) {
        if (finite(l.pts[k], l.pts[k + 1], l.pts[k + 2])) { s[0] += l.pts[k]; s[1] += l.pts[k + 1]; s[2] += l.pts[k + 2]; count++; }
      }
      for (let i = 0; count && i < 3; i++) { cmin[i] = Math.min(cmin[i], s[i] / count); cmax[i] = Math.max(cmax[i], s[i] / count); }
    }
    for (let i = 0; i < 3; i++) if (cmax[i] >= cmin[i]) travel[i] = Math.max(travel[i], cmax[i] - cmin[i]);
  }
  if (!(lo[0] <= hi[0])) { lo.fill(-1); hi.fill(1); lo[V] = 0; hi[V] = 1.8; }
  lo[V] = Math.min(lo[V], 0);
  const centre = [0, 1, 2].map((i) => (lo[i] + hi[i]) / 2);
  const extent = [0, 1, 2].map((i) => Math.max(hi[i] - lo[i], 0.5));

  // ---- three.js scene -------------------------------------------------------------------
  const canvas = $("mv-canvas"), stage = $("mv-stage");
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  } catch (error) {
    $("mv-title").textContent = "This browser cannot draw the view: WebGL is off or missing (" + error.message + ").";
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f6f8);
  const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 2000);
  camera.up.set(0, zUp ? 0 : 1, zUp ? 1 : 0);
  scene.add(new THREE.AmbientLight(0xffffff, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.8);
  sun.position.set(zUp ? 3 : 3, zUp ? -4 : 6, zUp ? 6 : 4);
  scene.add(sun);

  const vec = (a, b, c) => new THREE.Vector3(a, b, c);
  const along = (h1, h2, v) => { const p = [0, 0, 0]; p[H1] = h1; p[H2] = h2; p[V] = v; return vec(...p); };

  // floor grid in metres, lines on whole metres
  const span = 2 * Math.ceil(Math.max(extent[H1], extent[H2]) / 2 + 1);
  const grid = new THREE.GridHelper(span, span, 0x8a9099, 0xc9cdd2);
  if (zUp) grid.rotation.x = Math.PI / 2;
  grid.position.copy(along(Math.round(centre[H1]), Math.round(centre[H2]), 0));
  scene.add(grid);
  const axes = new THREE.AxesHelper(0.25);
  scene.add(axes);

  // markers and joints: one instanced sphere per point; bones: line segments
  const sphere = new THREE.SphereGeometry(1, 14, 10);
  for (const l of layers) {
    const material = new THREE.MeshLambertMaterial({ color: l.colour });
    l.mesh = new THREE.InstancedMesh(sphere, material, Math.max(l.count, 1));
    l.mesh.count = l.count;
    l.mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
    l.mesh.frustumCulled = false;
    l.mesh.userData.layer = l;
    const virtual = new Set(l.virtual);
    l.radius = new Float32Array(l.count).map((_, i) =>
      l.kind === "skeleton" ? 0.016 : virtual.has(i) ? 0.007 : 0.011);
    const m = l.mesh.instanceMatrix.array;
    for (let i = 0; i < l.count; i++) m[16 * i + 15] = 1;
    scene.add(l.mesh);
    const geometry = new THREE.BufferGeometry();
    l.lines = new Float32Array(l.bones.length * 3);
    geometry.setAttribute("position", new THREE.BufferAttribute(l.lines, 3).setUsage(THREE.DynamicDrawUsage));
    l.boneMesh = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: l.colour }));
    l.boneMesh.frustumCulled = false;
    scene.add(l.boneMesh);
  }

  function arrow(colour) {
    const a = new THREE.ArrowHelper(vec(0, 0, 1), vec(0, 0, 0), 1, colour, 0.08, 0.04);
    a.visible = false;
    a.frustumCulled = false;
    a.traverse((o) => { o.frustumCulled = false; });
    scene.add(a);
    return a;
  }
  for (const p of plates) {
    const c = p.corners, outline = new Float32Array(12);
    for (let k = 0; k < 12; k++) outline[k] = c[k] + (k % 3 === V ? 0.002 : 0);
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.BufferAttribute(outline, 3));
    scene.add(new THREE.LineLoop(geometry, new THREE.LineBasicMaterial({ color: 0x333333 })));
    p.arrow = arrow(p.colour);
  }
  for (const f of forces) f.arrow = arrow(f.colour);

  // ---- camera: from the side of the walk, the whole box in view ---------------------------
  const controls = new THREE.OrbitControls(camera, canvas);
  controls.enableDamping = false;
  function homeCamera() {
    const width = stage.clientWidth || 800, height = stage.clientHeight || 500;
    const aspect = width / height, half = Math.tan((camera.fov * Math.PI) / 360);
    const along1 = travel[H1] + travel[H2] > 0.2 ? travel[H1] >= travel[H2]   // walk along H1
      : extent[H1] >= extent[H2];
    const wide = along1 ? extent[H1] : extent[H2], deep = along1 ? extent[H2] : extent[H1];
    const distance = Math.max(2, (0.6 * Math.max(wide / aspect, extent[V])) / half + deep / 2);
    const target = along(centre[H1], centre[H2], centre[V]);
    const side = along1 ? along(0, -1, 0) : along(1, 0, 0);  // look across the walk
    const tilt = 0.35;                                     // ~20° above the horizon
    const offset = side.multiplyScalar(distance * Math.cos(tilt)).add(along(0, 0, distance * Math.sin(tilt)));
    camera.position.copy(target).add(offset);
    controls.target.copy(target);
    controls.update();
    dirty = true;
  }

  // ---- per-frame update -----------------------------------------------------------------
  let current = 0, time = 0, playing = false, speed = 1, dirty = true, last = null;
  const followed = layers[0];
  const followPoint = () => {
    if (!followed) return null;
    const f = frameOf(followed, time), n = followed.count * 3, s = [0, 0, 0];
    let count = 0;
    for (let k = f * n; k < f * n + n; k += 3) {
      const x = followed.pts[k], y = followed.pts[k + 1], z = followed.pts[k + 2];
      if (finite(x, y, z)) { s[0] += x; s[1] += y; s[2] += z; count++; }
    }
    return count ? vec(s[0] / count, s[1] / count, s[2] / count) : null;
  };

  function showLayer(l, f) {
    const base = f * l.count * 3, p = l.pts, m = l.mesh.instanceMatrix.array;
    for (let i = 0; i < l.count; i++) {
      const x = p[base + 3 * i], y = p[base + 3 * i + 1], z = p[base + 3 * i + 2];
      const ok = finite(x, y, z), s = ok ? l.radius[i] : 0, o = 16 * i;
      m[o] = s; m[o + 5] = s; m[o + 10] = s;
      m[o + 12] = ok ? x : 0; m[o + 13] = ok ? y : 0; m[o + 14] = ok ? z : 0;
    }
    l.mesh.instanceMatrix.needsUpdate = true;
    l.mesh.boundingSphere = null;
    const b = l.bones, out = l.lines;
    for (let k = 0; k < b.length; k += 2) {
      const i = base + 3 * b[k], j = base + 3 * b[k + 1];
      const ok = finite(p[i], p[i + 1], p[i + 2]) && finite(p[j], p[j + 1], p[j + 2]);
      for (let c = 0; c < 3; c++) {
        out[3 * k + c] = ok ? p[i + c] : 0;
        out[3 * k + 3 + c] = ok ? p[j + c] : 0;
      }
    }
    l.boneMesh.geometry.attributes.position.needsUpdate = true;
  }

  function showArrow(track, f, fallback) {
    const k = 3 * f, F = track.F, P = track.P;
    const size = Math.hypot(F[k], F[k + 1], F[k + 2]);
    let at = finite(P[k], P[k + 1], P[k + 2]) ? vec(P[k], P[k + 1], P[k + 2]) : fallback;
    track.shown = size >= ARROW_MIN_N && at ? size : 0;
    track.arrow.visible = track.shown > 0;
    if (!track.arrow.visible) return;
    track.arrow.position.copy(at);
    track.arrow.setDirection(vec(F[k] / size, F[k + 1] / size, F[k + 2] / size));
    track.arrow.setLength(size * FORCE_SCALE, 0.08, 0.04);
  }

  function readout() {
    const lines = [];
    for (const t of plates.concat(forces)) lines.push(`${t.name}: ${t.shown ? Math.round(t.shown) + " N" : "—"}`);
    $("mv-readout").textContent = lines.concat(D.notes).join("\n");
  }

  function setFrame(i, fromPlayer) {
    current = Math.max(0, Math.min(steps - 1, i | 0));
    if (!fromPlayer) time = current / stepRate;
    for (const l of layers) showLayer(l, frameOf(l, time));
    for (const p of plates) showArrow(p, frameOf(p, time), null);
    if (forces.length) {
      const under = followPoint();
      if (under) under.setComponent(V, 0);
      for (const f of forces) showArrow(f, frameOf(f, time), under);
    }
    if ($("mv-follow").checked) {
      const c = followPoint();
      if (c) {
        c.setComponent(V, controls.target.getComponent(V));
        camera.position.add(c.clone().sub(controls.target));
        controls.target.copy(c);
        controls.update();
      }
    }
    $("mv-scrub").value = String(current);
    $("mv-frame").textContent = `frame ${current + 1} / ${steps} · ${time.toFixed(3)} s`;
    readout();
    moveCursor();
    dirty = true;
  }

  // ---- hover: a marker's label ------------------------------------------------------------
  const raycaster = new THREE.Raycaster(), pointer = new THREE.Vector2();
  let hover = null;
  canvas.addEventListener("pointermove", (e) => {
    const r = canvas.getBoundingClientRect();
    hover = { x: e.clientX - r.left, y: e.clientY - r.top, w: r.width, h: r.height };
  });
  canvas.addEventListener("pointerleave", () => { hover = null; $("mv-tip").hidden = true; });
  function pick() {
    const tip = $("mv-tip");
    pointer.set((hover.x / hover.w) * 2 - 1, -(hover.y / hover.h) * 2 + 1);
    raycaster.setFromCamera(pointer, camera);
    const hits = raycaster.intersectObjects(layers.filter((l) => l.mesh.visible).map((l) => l.mesh), false)
      .filter((h) => h.instanceId !== undefined);
    if (!hits.length) { tip.hidden = true; return; }
    const l = hits[0].object.userData.layer;
    tip.textContent = `${l.labels[hits[0].instanceId]} · ${l.name}`;
    tip.style.left = hover.x + "px";
    tip.style.top = hover.y + "px";
    tip.hidden = false;
  }

  // ---- joint-angle curves with a cursor ---------------------------------------------------
  const svgNS = "http://www.w3.org/2000/svg";
  const plot = $("mv-plot");
  const M = { left: 46, right: 10, top: 8, bottom: 18 };
  let cursor = null, xOf = null, tOf = null;
  function drawCurves() {
    if (!curves) return;
    $("mv-curves").hidden = false;
    const W = plot.clientWidth || 800, Hh = plot.clientHeight || 170;
    plot.setAttribute("viewBox", `0 0 ${W} ${Hh}`);
    while (plot.firstChild) plot.removeChild(plot.firstChild);
    const n = curves.samples, k = curves.columns.length, t = curves.t, v = curves.v;
    const t1 = Math.max(duration, t[n - 1] || 0, 1e-9);
    let vmin = Infinity, vmax = -Infinity;
    curves.columns.forEach((_, c) => {
      if (curves.hidden && curves.hidden[c]) return;
      for (let s = 0; s < n; s++) { const y = v[s * k + c]; if (y === y) { vmin = Math.min(vmin, y); vmax = Math.max(vmax, y); } }
    });
    if (!(vmin <= vmax)) { vmin = -1; vmax = 1; }
    const pad = Math.max((vmax - vmin) * 0.06, 0.5);
    vmin -= pad; vmax += pad;
    xOf = (tt) => M.left + (tt / t1) * (W - M.left - M.right);
    tOf = (x) => ((x - M.left) / (W - M.left - M.right)) * t1;
    const yOf = (y) => M.top + ((vmax - y) / (vmax - vmin)) * (Hh - M.top - M.bottom);
    const el = (name, attrs, text) => {
      const e = document.createElementNS(svgNS, name);
      for (const a in attrs) e.setAttribute(a, attrs[a]);
      if (text !== undefined) e.textContent = text;
      plot.appendChild(e);
      return e;
    };
    el("rect", { x: M.left, y: M.top, width: W - M.left - M.right, height: Hh - M.top - M.bottom, fill: "#fafbfc", stroke: "#ccc" });
    // grid lines at round steps: degrees on the left, seconds below
    const nice = (span, count) => {
      const raw = span / count, power = Math.pow(10, Math.floor(Math.log10(raw)));
      return power * ([1, 2, 5, 10].find((m) => m * power >= raw) || 10);
    };
    const dv = nice(vmax - vmin, 5), dt = nice(t1, 8);
    for (let y = Math.ceil(vmin / dv) * dv; y <= vmax; y += dv) {
      el("line", { x1: M.left, x2: W - M.right, y1: yOf(y), y2: yOf(y), stroke: Math.abs(y) < dv / 2 ? "#bbb" : "#e6e6e6" });
      el("text", { x: M.left - 4, y: yOf(y) + 3, "text-anchor": "end", "font-size": 10 }, `${+y.toFixed(6)}°`);
    }
    for (let tt = 0; tt <= t1 + 1e-9; tt += dt) {
      el("line", { x1: xOf(tt), x2: xOf(tt), y1: M.top, y2: Hh - M.bottom, stroke: "#eee" });
      el("text", { x: xOf(tt), y: Hh - 4, "text-anchor": "middle", "font-size": 10 }, `${+tt.toFixed(6)} s`);
    }
    curves.columns.forEach((_, c) => {
      if (curves.hidden && curves.hidden[c]) return;
      let d = "", pen = "M";
      for (let s = 0; s < n; s++) {
        const y = v[s * k + c];
        if (y !== y) { pen = "M"; continue; }                 // an unknown angle: a gap
        d += `${pen}${xOf(t[s]).toFixed(1)} ${yOf(y).toFixed(1)}`;
        pen = "L";
      }
      if (d) el("path", { d, fill: "none", stroke: CURVE_COLOURS[c % CURVE_COLOURS.length], "stroke-width": 1.4, "data-column": curves.columns[c] });
    });
    cursor = el("line", { id: "mv-cursor", y1: M.top, y2: Hh - M.bottom, stroke: "#111", "stroke-width": 1.2 });
    moveCursor();
  }
  function moveCursor() {
    if (!cursor || !xOf) return;
    const x = xOf(time).toFixed(2);
    cursor.setAttribute("x1", x);
    cursor.setAttribute("x2", x);
    if (!curves.labels) return;
    const n = curves.samples, k = curves.columns.length;
    let s = 0;                                                  // the sample at the cursor
    while (s + 1 < n && curves.t[s + 1] <= time + 1e-9) s++;
    curves.labels.forEach((span, c) => {
      const y = curves.v[s * k + c];
      span.textContent = `${curves.columns[c]} ${y === y ? y.toFixed(1) + "°" : "—"}`;
    });
  }
  if (curves) {
    const legend = $("mv-curve-legend");
    curves.hidden = curves.columns.map(() => false);
    curves.labels = curves.columns.map((name, c) => {
      const label = document.createElement("label");
      const box = document.createElement("input");
      box.type = "checkbox"; box.checked = true;
      box.addEventListener("change", () => { curves.hidden[c] = !box.checked; drawCurves(); });
      const swatch = document.createElement("i");
      swatch.style.background = CURVE_COLOURS[c % CURVE_COLOURS.length];
      const text = document.createElement("span");
      label.append(box, swatch, text);
      legend.appendChild(label);
      return text;
    });
    const seekAt = (e) => {
      if (!tOf) return;
      const r = plot.getBoundingClientRect();
      const x = ((e.clientX - r.left) / r.width) * (plot.viewBox.baseVal.width || r.width);
      setFrame(Math.round(Math.max(0, tOf(x)) * stepRate), false);
    };
    plot.addEventListener("pointerdown", (e) => { seekAt(e); plot.setPointerCapture(e.pointerId); });
    plot.addEventListener("pointermove", (e) => { if (e.buttons & 1) seekAt(e); });
  }

  // ---- legend, controls, loop -------------------------------------------------------------
  $("mv-title").textContent = D.title || "";
  for (const l of layers) {
    const label = document.createElement("label"), box = document.createElement("input");
    box.type = "checkbox"; box.checked = true;
    box.addEventListener("change", () => { l.mesh.visible = l.boneMesh.visible = box.checked; dirty = true; });
    const swatch = document.createElement("i");
    swatch.style.background = l.colour;
    const what = l.kind === "skeleton" ? `${l.count} joints` : `${l.count} markers` + (l.skeleton ? `, ${l.skeleton}` : "");
    label.append(box, swatch, `${l.name} (${what}, ${l.rate.toFixed(l.rate % 1 ? 2 : 0)} Hz)`);
    $("mv-legend").appendChild(label);
  }
  const scrub = $("mv-scrub");
  scrub.max = String(steps - 1);
  const setPlaying = (on) => {
    playing = on && steps > 1;
    last = null;
    $("mv-play").innerHTML = playing ? "&#10074;&#10074;" : "&#9654;";
    if (playing && current >= steps - 1) setFrame(0, false);
  };
  scrub.addEventListener("input", () => { setPlaying(false); setFrame(+scrub.value, false); });
  $("mv-play").addEventListener("click", () => setPlaying(!playing));
  $("mv-prev").addEventListener("click", () => { setPlaying(false); setFrame(current - 1, false); });
  $("mv-next").addEventListener("click", () => { setPlaying(false); setFrame(current + 1, false); });
  $("mv-speed").addEventListener("change", (e) => { speed = +e.target.value; });
  $("mv-reset").addEventListener("click", homeCamera);
  $("mv-follow").addEventListener("change", () => setFrame(current, true));
  controls.addEventListener("change", () => { dirty = true; });
  window.addEventListener("keydown", (e) => {
    if (e.target && (e.target.tagName === "SELECT" || e.target.tagName === "INPUT" && e.target.type !== "range")) return;
    if (e.key === " ") { setPlaying(!playing); e.preventDefault(); }
    else if (e.key === "ArrowLeft") { setPlaying(false); setFrame(current - 1, false); e.preventDefault(); }
    else if (e.key === "ArrowRight") { setPlaying(false); setFrame(current + 1, false); e.preventDefault(); }
  });

  function resize() {
    const width = stage.clientWidth, height = stage.clientHeight;
    if (!width || !height) return;
    renderer.setSize(width, height, false);
    camera.aspect = width / height;
    camera.updateProjectionMatrix();
    drawCurves();
    dirty = true;
  }
  new ResizeObserver(resize).observe(stage);
  resize();
  homeCamera();
  setFrame(0, false);

  function tick(now) {
    requestAnimationFrame(tick);
    if (playing) {
      if (last !== null) {
        time += ((now - last) / 1000) * speed;
        if (time > duration) time = 0;                       // play loops
        setFrame(Math.floor(time * stepRate + 1e-9), true);
      }
      last = now;
    }
    if (hover) pick();
    if (dirty) { renderer.render(scene, camera); dirty = false; }
  }
  requestAnimationFrame(tick);

  window.mocapView = {
    get frame() { return current; }, get frames() { return steps; }, get time() { return time; },
    get playing() { return playing; }, get rate() { return stepRate; },
    play() { setPlaying(true); }, pause() { setPlaying(false); },
    seek(i) { setPlaying(false); setFrame(i, false); }, setSpeed(s) { speed = +s; },
    // what is drawn now, for scripts and tests: is a point shown (not a gap), where on the
    // page (client pixels), and the force arrows
    drawn(layer, point) { return layers[layer].mesh.instanceMatrix.array[16 * point] > 0; },
    screenPosition(layer, point) {
      const l = layers[layer], m = l.mesh.instanceMatrix.array, o = 16 * point;
      if (!(m[o] > 0)) return null;
      const p = vec(m[o + 12], m[o + 13], m[o + 14]).project(camera), r = canvas.getBoundingClientRect();
      return [r.left + ((p.x + 1) / 2) * r.width, r.top + ((1 - p.y) / 2) * r.height];
    },
    arrows() {
      return plates.concat(forces).map((t) => ({ name: t.name, visible: t.arrow.visible, newtons: t.shown,
        position: t.arrow.position.toArray(), length: t.shown * FORCE_SCALE }));
    },
    render() { renderer.render(scene, camera); dirty = false; },
    camera, scene, renderer,
  };
})();
