// flexstar animate: draws frame k of every run; positions in the JSON are integer micrometres
// (rigid) and nanometres (elastic part); the drawing is in millimetres, y up.
"use strict";
const D = JSON.parse(document.getElementById("frames-data").textContent);
const N = D.times.length, T_END = D.times[N - 1];
const $ = (id) => document.getElementById(id);
let M = D.magnify, k = 0, playing = false, simT = 0, last = null;

function bounds() {
  let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
  const add = (x, y) => { x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); };
  for (const r of D.rails) { add(r[0], r[1]); add(r[2], r[3]); }
  for (const c of D.base) add(c[0], c[1]);
  for (const run of D.runs) for (const f of run.rigid) for (const b of f)
    for (let j = 0; j < b.length; j += 2) add(b[j], b[j + 1]);
  const pad = 0.15 * Math.max(x1 - x0, y1 - y0) + 0.1 * D.L_um;
  return [x0 - pad, y0 - pad, x1 - x0 + 2 * pad, y1 - y0 + 2 * pad].map((v) => v / 1000);
}

function setup() {
  const [x, y, w, h] = bounds();
  $("view").setAttribute("viewBox", `${x} ${-(y + h)} ${w} ${h}`);
  const line = (cls, colour, width, extra) =>
    `<polyline class="${cls}" fill="none" stroke="${colour}" stroke-width="${width}" vector-effect="non-scaling-stroke" ${extra || ""}/>`;
  let s = "";
  // the base triangle: its sides are the sliders' rails (grey), the travel of this motion darker
  if (D.base.length === 3) s += `<polygon class="base" points="${D.base.map((c) => `${c[0] / 1000},${c[1] / 1000}`).join(" ")}" fill="#f3f5f8" stroke="#b8c2cc" stroke-width="1.5" vector-effect="non-scaling-stroke"/>`;
  for (const r of D.rails) s += `<line x1="${r[0] / 1000}" y1="${r[1] / 1000}" x2="${r[2] / 1000}" y2="${r[3] / 1000}" stroke="#8899aa" stroke-width="3" vector-effect="non-scaling-stroke"/>`;
  D.runs.forEach((run, i) => {
    s += line(`trace r${i}`, run.colour, 1, 'stroke-dasharray="4 3" opacity="0.6"');
    for (let b = 0; b < 3; b++) s += line(`rigid r${i}`, "#999", 1);
    // later runs narrower, drawn over the earlier ones: where they agree both stay visible
    for (let b = 0; b < 3; b++) s += line(`beam r${i}`, run.colour, Math.max(1.5, 5 - 2 * i));
  });
  D.runs.forEach((run, i) => {
    if (D.payload) s += `<polygon class="payload r${i}" fill="${run.colour}" fill-opacity="0.35" stroke="${run.colour}" stroke-width="1.5" vector-effect="non-scaling-stroke"/>`;
  });
  for (let i = 0; i < 3; i++) s += `<polygon class="slider" fill="#4477aa" stroke="#223" stroke-width="1" vector-effect="non-scaling-stroke"/>`;
  $("scene").innerHTML = s;
  $("scene").setAttribute("transform", "scale(1,-1)");
  $("legend").innerHTML = '<span style="color:#999">&#9473; rigid star</span>' +
    D.runs.map((r) => `<span style="color:${r.colour}">&#9473; ${r.name}</span>`).join("") +
    (D.base.length === 3 ? '<span style="color:#4477aa">&#9632; sliders on the base triangle</span>' : "") +
    (D.payload ? `<span>&#9634; payload ${D.payload.mass} kg at G + (${D.payload.offset[0] / 1000}, ${D.payload.offset[1] / 1000}) mm in the star's frame</span>` : "") +
    `<span>deformed beams: rigid + elastic part x M</span>`;
  $("slider").max = N - 1;
  if (D.t_rest !== null && D.t_rest <= T_END) {
    $("rest").style.left = `${(100 * D.t_rest) / T_END}%`;
    $("rest").textContent = `\u25b2 t_rest = ${D.t_rest} s`;
  }
}

function draw() {
  const scene = $("scene");
  D.runs.forEach((run, i) => {
    const rigid = scene.querySelectorAll(`.rigid.r${i}`), beams = scene.querySelectorAll(`.beam.r${i}`);
    for (let b = 0; b < 3; b++) {
      const r = run.rigid[k][b], e = run.elastic[k][b];
      let pr = "", pd = "";
      for (let j = 0; j < r.length; j += 2) {
        pr += `${r[j] / 1000},${r[j + 1] / 1000} `;
        pd += `${(r[j] + (M * e[j]) / 1000) / 1000},${(r[j + 1] + (M * e[j + 1]) / 1000) / 1000} `;
      }
      rigid[b].setAttribute("points", pr);
      beams[b].setAttribute("points", pd);
    }
    const tr = run.G.slice(0, k + 1).map((g) => `${g[0] / 1000},${g[1] / 1000}`).join(" ");
    scene.querySelector(`.trace.r${i}`).setAttribute("points", tr);
  });
  // a slider: a block along its rail u_i, 0.08 L long and 0.04 L wide, centred on its revolute point
  const U = [[1, 0], [-0.5, Math.sqrt(3) / 2], [-0.5, -Math.sqrt(3) / 2]];
  const block = (cx, cy, ux, uy, a, b) =>
    [[a, b], [-a, b], [-a, -b], [a, -b]].map(([p, q]) => `${(cx + p * ux - q * uy) / 1000},${(cy + p * uy + q * ux) / 1000}`).join(" ");
  if (D.sliders.length) scene.querySelectorAll(".slider").forEach((c, i) => {
    c.setAttribute("points", block(D.sliders[k][2 * i], D.sliders[k][2 * i + 1], U[i][0], U[i][1], D.L_um / 25, D.L_um / 50));
  });
  // the payload: a square 0.06 L wide about its centre of mass, G (deformed) + offset in the
  // star's frame (e_x1 = [sin th, -cos th], e_w1 = [cos th, sin th]), turned with the star
  if (D.payload) D.runs.forEach((run, i) => {
    const r = run.rigid[k][0], e = run.elastic[k][0], th = run.theta[k] / 1e6;
    const gx = r[0] + (M * e[0]) / 1000, gy = r[1] + (M * e[1]) / 1000;
    const [ox, oy] = D.payload.offset, ex = [Math.sin(th), -Math.cos(th)], ew = [Math.cos(th), Math.sin(th)];
    const px = gx + ox * ex[0] + oy * ew[0], py = gy + ox * ex[1] + oy * ew[1];
    scene.querySelector(`.payload.r${i}`).setAttribute("points", block(px, py, ex[0], ex[1], 0.03 * D.L_um, 0.03 * D.L_um));
  });
  $("slider").value = k;
  $("readout").textContent = `t = ${D.times[k].toFixed(3)} s (frame ${k + 1} of ${N}), elastic part x ${M}`;
}

function frameAt(t) {
  let best = 0;
  for (let j = 0; j < N; j++) if (Math.abs(D.times[j] - t) < Math.abs(D.times[best] - t)) best = j;
  return best;
}

function tick(now) {
  if (!playing) return;
  if (last !== null) simT += ((now - last) / 1000) * parseFloat($("speed").value);
  last = now;
  if (simT > T_END) simT = 0;
  k = frameAt(simT);
  draw();
  requestAnimationFrame(tick);
}

function toggle() {
  playing = !playing;
  $("play").textContent = playing ? "pause" : "play";
  last = null;
  simT = D.times[k];
  if (playing) requestAnimationFrame(tick);
}

function fromHash() {
  const h = new URLSearchParams(location.hash.replace(/^#/, ""));
  if (h.has("t") && isFinite(parseFloat(h.get("t")))) k = frameAt(parseFloat(h.get("t")));
  if (h.has("m") && parseFloat(h.get("m")) >= 0) M = parseFloat(h.get("m"));
  $("mag").value = M;
}

setup();
fromHash();
draw();
$("slider").addEventListener("input", () => { k = parseInt($("slider").value, 10); simT = D.times[k]; draw(); });
$("mag").addEventListener("input", () => { const v = parseFloat($("mag").value); if (v >= 0) { M = v; draw(); } });
$("play").addEventListener("click", toggle);
window.addEventListener("hashchange", () => { fromHash(); draw(); });
document.addEventListener("keydown", (ev) => { if (ev.code === "Space" && ev.target.tagName !== "INPUT") { ev.preventDefault(); toggle(); } });
