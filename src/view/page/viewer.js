// heron view's page. The server draws every view as RGBA with heron's own display
// transform (src/view/show.rs); this script only places it on the canvas, zooms and
// pans, and asks the server about the pixel under the pointer. State a test can read
// is on window.heronViewer.
"use strict";

const $ = (id) => document.getElementById(id);
const S = {
  images: [], generation: -1,
  a: 0, b: 1, showing: 0,          // A, B and which of them is on screen
  view: "rgb", ev: 0, mode: "hue",
  zoom: 1, ox: 0, oy: 0, fitted: true,
  picture: null, overlay: null,    // offscreen canvases: the view (one pixel per step×step
  step: 1,                         // block of the image) and the z-map (the image's size)
  pinned: null, hover: null, busy: false, queued: null,
  drawn: 0,                        // pictures drawn so far (tests wait on it)
};
window.heronViewer = S;
S.zoomTo = (z, cx, cy) => zoomTo(z, cx, cy);

function status(text, error) {
  const f = $("status");
  f.textContent = text;
  f.className = error ? "error" : "";
}

async function fetchOk(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: ${r.status} ${(await r.text()).trim()}`);
  return r;
}

const fmt = (v) => (v === null || v === undefined ? "–" : Number(v).toPrecision(6));
const fmt3 = (a) => (a ? a.map(fmt).join(", ") : "–");

async function loadList() {
  const list = await (await fetchOk("/api/images")).json();
  S.images = list.images;
  S.generation = list.generation;
  if (S.a >= S.images.length) S.a = 0;
  if (S.b >= S.images.length) S.b = Math.min(1, S.images.length - 1);
  const files = $("files");
  files.replaceChildren();
  S.images.forEach((img, i) => {
    const btn = document.createElement("button");
    btn.textContent = img.name.split("/").pop();
    btn.title = img.name;
    btn.dataset.index = i;
    btn.onclick = () => { S.a = i; S.showing = i; refresh(); };
    files.appendChild(btn);
  });
  const bsel = $("b-file");
  bsel.replaceChildren(...S.images.map((img, i) => new Option(img.name.split("/").pop(), i)));
  bsel.value = S.b;
  document.querySelector(".ab").style.display = S.images.length > 1 ? "" : "none";
}

function current() { return S.images[S.showing]; }

function fillViews() {
  const img = current();
  const sel = $("view");
  sel.replaceChildren(...img.views.map((v) => new Option(v.label, v.id)));
  if (!img.views.some((v) => v.id === S.view)) S.view = img.views[0].id;
  sel.value = S.view;
  const prov = $("provenance");
  prov.replaceChildren(...img.provenance.map(([k, v]) => row(k, v)));
  if (!img.provenance.length) prov.replaceChildren(row("", "none (a render in progress, or not written by heron)"));
  for (const btn of $("files").children) {
    btn.classList.toggle("current", Number(btn.dataset.index) === S.showing);
  }
}

function row(k, v) {
  const tr = document.createElement("tr");
  const th = document.createElement("th");
  const td = document.createElement("td");
  th.textContent = k;
  td.textContent = v;
  tr.append(th, td);
  return tr;
}

function toCanvas(bytes, w, h) {
  const c = document.createElement("canvas");
  c.width = w;
  c.height = h;
  c.getContext("2d").putImageData(new ImageData(new Uint8ClampedArray(bytes), w, h), 0, 0);
  return c;
}

// Fetches the picture of the image on screen and the z-map if asked for, then draws.
async function refresh() {
  const img = current();
  if (!img) return;
  fillViews();
  if (S.fitted) fit();
  // Shown smaller than its size, the image is fetched one pixel per block of `step`
  // pixels (block means, drawn by the server): a 4K file fitted to a window is a
  // sixteenth of the bytes. Zooming in past the block size fetches it again.
  const step = wantedStep();
  const q = `view=${encodeURIComponent(S.view)}&ev=${S.ev}&mode=${S.mode}&step=${step}`;
  try {
    const r = await fetchOk(`/api/image/${S.showing}/view?${q}`);
    S.picture = toCanvas(await r.arrayBuffer(), Number(r.headers.get("X-Width")),
                         Number(r.headers.get("X-Height")));
    S.step = step;
    S.overlay = null;
    if ($("zmap").checked && S.images.length > 1) {
      const z = await fetchOk(`/api/compare/${S.a}/${S.b}`);
      S.overlay = toCanvas(await z.arrayBuffer(), img.width, img.height);
      const same = z.headers.get("X-Heron-Same") === "true";
      $("compare-status").textContent =
        `${S.images[S.a].name} against ${S.images[S.b].name}: ${same ? "same" : "different"} ` +
        `up to noise (max |z| ${z.headers.get("X-Heron-Max-Abs-Z")}, ` +
        `${z.headers.get("X-Heron-Tests")} tests, Šidák α = 0.01)`;
    }
    draw();
    S.drawn += 1;
    const which = S.images.length > 1 ? (S.showing === S.a ? "A: " : "B: ") : "";
    const z = S.overlay ? `  ·  z-map: ${$("compare-status").textContent}` : "";
    status(`${which}${img.name}  ${img.width}×${img.height}  ${S.view}  ${S.ev} EV  zoom ${S.zoom.toPrecision(3)}${z}`);
    const p = S.pinned || S.hover;
    if (p) inspect(p.x, p.y);
  } catch (e) {
    status(String(e.message || e), true);
  }
}

function wantedStep() {
  return Math.max(1, Math.min(256, Math.floor(1 / S.zoom)));
}

function fit() {
  const img = current();
  const vp = $("viewport");
  S.zoom = Math.min(vp.clientWidth / img.width, vp.clientHeight / img.height);
  S.ox = (vp.clientWidth - img.width * S.zoom) / 2;
  S.oy = (vp.clientHeight - img.height * S.zoom) / 2;
  S.fitted = true;
}

function draw() {
  const vp = $("viewport");
  const c = $("canvas");
  if (c.width !== vp.clientWidth || c.height !== vp.clientHeight) {
    c.width = vp.clientWidth;
    c.height = vp.clientHeight;
  }
  const ctx = c.getContext("2d");
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.clearRect(0, 0, c.width, c.height);
  if (!S.picture) return;
  // Nearest neighbour once pixels are magnified: they stay squares to inspect.
  ctx.imageSmoothingEnabled = S.zoom < 1;
  ctx.setTransform(S.zoom * S.step, 0, 0, S.zoom * S.step, S.ox, S.oy);
  ctx.drawImage(S.picture, 0, 0);
  ctx.setTransform(S.zoom, 0, 0, S.zoom, S.ox, S.oy);
  if (S.overlay) {
    ctx.globalAlpha = Number($("zmap-alpha").value);
    ctx.drawImage(S.overlay, 0, 0);
    ctx.globalAlpha = 1;
  }
  if (S.pinned) {
    // Magnified: the pixel's outline; otherwise a ring around it, in screen pixels.
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.lineWidth = 2;
    ctx.strokeStyle = "#ff0";
    const x = S.ox + S.pinned.x * S.zoom, y = S.oy + S.pinned.y * S.zoom;
    ctx.beginPath();
    if (S.zoom >= 4) ctx.rect(x, y, S.zoom, S.zoom);
    else ctx.arc(x + S.zoom / 2, y + S.zoom / 2, 7, 0, 2 * Math.PI);
    ctx.stroke();
  }
}

function pixelAt(ev) {
  const r = $("canvas").getBoundingClientRect();
  const x = Math.floor((ev.clientX - r.left - S.ox) / S.zoom);
  const y = Math.floor((ev.clientY - r.top - S.oy) / S.zoom);
  const img = current();
  return x >= 0 && y >= 0 && x < img.width && y < img.height ? { x, y } : null;
}

// One request in flight; the latest position waits for it.
async function inspect(x, y) {
  if (S.busy) { S.queued = { x, y }; return; }
  S.busy = true;
  try {
    const r = await fetchOk(`/api/image/${S.showing}/pixel?x=${x}&y=${y}`);
    showPixel(await r.json());
  } catch (e) {
    status(String(e.message || e), true);
  } finally {
    S.busy = false;
    if (S.queued) { const q = S.queued; S.queued = null; inspect(q.x, q.y); }
  }
}

function showPixel(p) {
  $("px-xy").textContent = `(${p.x}, ${p.y})`;
  $("px-xy").dataset.x = p.x;
  $("px-xy").dataset.y = p.y;
  $("px-pinned").textContent = S.pinned ? "pinned" : "";
  $("px-rgb").textContent = fmt3(p.rgb);
  $("px-xyz").textContent = fmt3(p.xyz);
  $("px-stderr").textContent = fmt3(p.stderr);
  $("px-stokes").textContent = p.stokes
    ? `S1 ${fmt3(p.stokes.s1)}; S2 ${fmt3(p.stokes.s2)}; S3 ${fmt3(p.stokes.s3)}; ` +
      `DoLP ${fmt(p.stokes.dolp)}, AoLP ${fmt(p.stokes.aolp_deg)}°`
    : "–";
  $("channel-table").replaceChildren(...p.channels.map(([k, v]) => row(k, fmt(v))));
  const sp = p.spectrum;
  const table = $("spectrum-table");
  table.replaceChildren();
  sp.lambda.forEach((l, i) => {
    const tr = row(`${l} nm`, ["s0", "s1", "s2", "s3"].filter((k) => sp[k]).map((k) => fmt(sp[k][i])).join(", "));
    tr.dataset.lambda = l;
    tr.dataset.s0 = sp.s0[i];
    table.appendChild(tr);
  });
  plotSpectrum(sp);
}

// S0 over the bins (white) and S1–S3 (red, green, blue) when the render was polarised.
function plotSpectrum(sp) {
  const svg = $("spectrum");
  const ns = "http://www.w3.org/2000/svg";
  svg.replaceChildren();
  if (!sp.lambda.length) {
    const t = document.createElementNS(ns, "text");
    t.setAttribute("x", 10); t.setAttribute("y", 90);
    t.textContent = "no spectral bins (heron render --spectral-bins N)";
    svg.appendChild(t);
    return;
  }
  const series = [["s0", "#eee"], ["s1", "#e55"], ["s2", "#5c5"], ["s3", "#58f"]].filter(([k]) => sp[k]);
  const vals = series.flatMap(([k]) => sp[k]).filter((v) => v !== null && isFinite(v));
  const lo = Math.min(0, ...vals), hi = Math.max(1e-30, ...vals);
  const [l0, l1] = [sp.lambda[0], sp.lambda[sp.lambda.length - 1]];
  const X = (l) => 36 + (l1 > l0 ? (l - l0) / (l1 - l0) : 0.5) * 274;
  const Y = (v) => 160 - ((v - lo) / (hi - lo)) * 150;
  const line = (x1, y1, x2, y2, c) => {
    const e = document.createElementNS(ns, "line");
    Object.entries({ x1, y1, x2, y2, stroke: c }).forEach(([k, v]) => e.setAttribute(k, v));
    svg.appendChild(e);
  };
  const text = (x, y, s, anchor) => {
    const e = document.createElementNS(ns, "text");
    e.setAttribute("x", x); e.setAttribute("y", y);
    if (anchor) e.setAttribute("text-anchor", anchor);
    e.textContent = s;
    svg.appendChild(e);
  };
  line(36, 160, 310, 160, "#666");
  line(36, 10, 36, 160, "#666");
  if (lo < 0) line(36, Y(0), 310, Y(0), "#444");
  text(36, 174, `${l0}`, "middle");
  text(310, 174, `${l1} nm`, "end");
  text(33, 14, hi.toPrecision(3), "end");
  text(33, 160, lo.toPrecision(2), "end");
  for (const [k, c] of series) {
    const pts = sp.lambda.map((l, i) => [X(l), Y(sp[k][i] ?? 0)]);
    const e = document.createElementNS(ns, "polyline");
    e.setAttribute("points", pts.map((p) => p.join(",")).join(" "));
    e.setAttribute("fill", "none");
    e.setAttribute("stroke", c);
    e.dataset.series = k;
    svg.appendChild(e);
  }
}

function setEv(v) {
  v = Math.max(-16, Math.min(16, Number(v) || 0));
  S.ev = Math.round(v * 10) / 10;
  $("ev").value = S.ev;
  $("ev-num").value = S.ev;
  refresh();
}

function flip() {
  if (S.images.length < 2) return;
  S.showing = S.showing === S.a ? S.b : S.a;
  refresh();
}

function wire() {
  $("view").onchange = (e) => { S.view = e.target.value; refresh(); };
  $("ev").oninput = (e) => setEv(e.target.value);
  $("ev-num").onchange = (e) => setEv(e.target.value);
  $("mode").onchange = (e) => { S.mode = e.target.value; refresh(); };
  $("fit").onclick = () => { fit(); if (wantedStep() < S.step) refresh(); else draw(); };
  $("one").onclick = () => zoomTo(1, $("viewport").clientWidth / 2, $("viewport").clientHeight / 2);
  $("flip").onclick = flip;
  $("b-file").onchange = (e) => { S.b = Number(e.target.value); refresh(); };
  $("zmap").onchange = refresh;
  $("zmap-alpha").oninput = draw;
  const vp = $("viewport");
  let drag = null;
  vp.onmousedown = (e) => { drag = { x: e.clientX, y: e.clientY, ox: S.ox, oy: S.oy, moved: false }; };
  window.onmouseup = () => { setTimeout(() => { drag = null; }, 0); };
  vp.onmousemove = (e) => {
    if (drag && e.buttons) {
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      if (Math.abs(dx) + Math.abs(dy) > 3) drag.moved = true;
      if (drag.moved) {
        S.ox = drag.ox + dx; S.oy = drag.oy + dy; S.fitted = false;
        draw();
        return;
      }
    }
    const p = pixelAt(e);
    if (p && !S.pinned) { S.hover = p; inspect(p.x, p.y); }
  };
  vp.onclick = (e) => {
    if (drag && drag.moved) return;
    const p = pixelAt(e);
    S.pinned = p && !(S.pinned && S.pinned.x === p.x && S.pinned.y === p.y) ? p : null;
    if (p) inspect(p.x, p.y);
    draw();
  };
  vp.onwheel = (e) => {
    e.preventDefault();
    const r = $("canvas").getBoundingClientRect();
    zoomTo(S.zoom * Math.pow(2, -e.deltaY / 300), e.clientX - r.left, e.clientY - r.top);
  };
  window.onresize = () => { if (S.fitted) fit(); draw(); };
  window.onkeydown = (e) => {
    if (e.target.tagName === "INPUT" || e.target.tagName === "SELECT") return;
    if (e.key === "f" || e.key === "F") flip();
    else if (e.key === "0") $("fit").onclick();
    else if (e.key === "1") $("one").onclick();
    else if (e.key === "+" || e.key === "=") setEv(S.ev + 0.5);
    else if (e.key === "-") setEv(S.ev - 0.5);
  };
}

// Zooms about a point of the viewport, which stays over the same image point.
function zoomTo(z, cx, cy) {
  z = Math.max(1 / 64, Math.min(256, z));
  S.ox = cx - ((cx - S.ox) * z) / S.zoom;
  S.oy = cy - ((cy - S.oy) * z) / S.zoom;
  S.zoom = z;
  // At whole zoom factors pixels land on whole screen pixels: no half-pixel seams.
  if (z >= 1 && Number.isInteger(z)) { S.ox = Math.round(S.ox); S.oy = Math.round(S.oy); }
  S.fitted = false;
  if (wantedStep() < S.step) refresh();
  else draw();
}

// A render in progress (heron render --view) bumps the generation as passes finish.
async function poll() {
  try {
    const g = (await (await fetchOk("/api/generation")).json()).generation;
    if (g !== S.generation) {
      await loadList();
      await refresh();
    }
  } catch (e) {
    status(`the server is gone (${e.message || e})`, true);
  }
  setTimeout(poll, 1000);
}

async function main() {
  wire();
  try {
    await loadList();
    if (!S.images.length) status("waiting for the render's first pass…");
    else await refresh();
  } catch (e) {
    status(String(e.message || e), true);
  }
  setTimeout(poll, 1000);
}

main();
