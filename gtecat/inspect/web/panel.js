// gtecat panel: plain JavaScript, no build step, no network beyond this page's own server.
"use strict";
(() => {
const $ = (id) => document.getElementById(id);
const AL = {0: "NONE", 1: "INIT", 2: "PREOP", 3: "BOOT", 4: "SAFEOP", 8: "OP"};
const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
  "#17becf", "#7f7f7f", "#bcbd22", "#393b79", "#ad494a"];
const S = {
  layout: null, snap: null, control: false, bytes: new Uint8Array(0), snaps: 0, rateT0: 0,
  entries: [], axisCards: {}, wkcs: [], ioBits: [], logStart: 0, odRows: [],
  scope: {names: [], rows: [], paused: false, window: 2000, running: false},
};
window.gtecat = S;
let ws, nextId = 1;
const waiting = {};

function toast(text) {
  const t = $("toast"); t.textContent = text; t.style.display = "block";
  clearTimeout(toast.timer); toast.timer = setTimeout(() => { t.style.display = "none"; }, 4000);
}
function ask(op, ...args) {
  return new Promise((resolve, reject) => {
    const id = nextId++;
    waiting[id] = {resolve, reject};
    ws.send(JSON.stringify({id, op, args}));
  });
}
S.ask = ask;
function el(tag, attrs = {}, text) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
}
const hex = (v, w) => "0x" + v.toString(16).toUpperCase().padStart(w, "0");

// --- the process image ------------------------------------------------------------------
function bitsAt(bytes, bit, n) {  // little-endian, LSB first (the ENI's bit order)
  let v = 0n;
  for (let i = 0; i < n; i++) {
    const b = bit + i;
    if (bytes[b >> 3] >> (b & 7) & 1) v |= 1n << BigInt(i);
  }
  return v;
}
function entryValue(e) {
  const base = (e.dir === "out" ? 0 : S.layout.inputs_offset * 8) + e.logical_bit;
  const raw = bitsAt(S.bytes, base, e.bits);
  let value;
  const t = (e.type || "").toUpperCase();
  if ((t === "REAL" || t === "REAL32") && e.bits === 32) {
    const dv = new DataView(new ArrayBuffer(4)); dv.setUint32(0, Number(raw), true);
    value = dv.getFloat32(0, true);
  } else if (e.signed && e.bits > 1 && raw >> BigInt(e.bits - 1) & 1n) {
    value = raw - (1n << BigInt(e.bits));
  } else value = raw;
  const nbytes = Math.max(1, Math.ceil(e.bits / 8));
  let rawHex = "";
  for (let i = 0; i < nbytes; i++) rawHex += Number(raw >> BigInt(8 * i) & 0xFFn).toString(16).padStart(2, "0") + " ";
  return {value: typeof value === "bigint" ? Number(value) : value, raw, rawHex: rawHex.trim()};
}
function findEntry(slave, index, sub, dir) {
  return S.entries.find((e) => e.slave === slave && e.index === index && (sub === undefined || e.subindex === sub)
    && (!dir || e.dir === dir));
}

// --- building the page from the layout ------------------------------------------------------
function buildLayout(lay) {
  S.layout = lay;
  S.entries = [];
  for (const s of lay.slaves) for (const e of s.entries) {
    if (e.index === 0 && !e.name) continue;
    S.entries.push({...e, slave: s.position});
  }
  // slaves
  const tb = $("slaves").tBodies[0]; tb.innerHTML = "";
  const od = $("od-slave"); od.innerHTML = "";
  for (const s of lay.slaves) {
    const tr = el("tr", {"data-slave": s.position});
    tr.append(el("td", {}, s.position), el("td", {}, s.name), el("td", {class: "al"}, "-"),
      el("td", {class: "code"}, "-"), el("td", {}, s.axis === null ? "-" : String(s.axis)),
      el("td", {}, `${s.gt_offset} + ${s.gt_size}`));
    tb.append(tr);
    od.append(el("option", {value: s.position}, `${s.position} ${s.name}`));
  }
  // entries
  const eb = $("entries").tBodies[0]; eb.innerHTML = "";
  for (const e of S.entries) {
    const tr = el("tr");
    e.valueCell = el("td", {class: "num"}); e.rawCell = el("td", {class: "mono"});
    tr.append(el("td", {}, e.slave), el("td", {}, e.dir), el("td", {class: "mono"}, `${hex(e.index, 4)}:${hex(e.subindex, 2).slice(2)}`),
      el("td", {}, e.name), el("td", {}, e.type || `${e.bits} bit`), e.valueCell, e.rawCell,
      el("td", {class: "num"}, `${e.gt_bit >> 3}` + (e.gt_bit & 7 ? `.${e.gt_bit & 7}` : "")),
      el("td", {class: "num"}, e.logical_bit));
    eb.append(tr);
  }
  buildAxes(lay); buildIo(lay); buildScopePicks(lay);
}

function bitRow(names, cls) {
  const d = el("div", {class: "bits " + cls});
  const spans = {};
  for (const [b, n] of Object.entries(names)) { const s = el("span", {class: "bit", title: `bit ${b}`}, n); d.append(s); spans[b] = s; }
  return [d, spans];
}
function buildAxes(lay) {
  const root = $("axis-cards"); root.innerHTML = ""; S.axisCards = {};
  for (const a of lay.axes) {
    const c = el("div", {class: "card", "data-axis": a.axis});
    c.append(el("h3", {}, `Axis ${a.axis} (slave ${a.slave})`));
    const kv = el("div", {class: "kv"}); const v = {};
    for (const [k, label] of [["state", "CiA-402 state"], ["mode", "6060h / 6061h mode"], ["prf", "planned position (pulse)"],
      ["enc", "encoder position"], ["vel", "velocity (pulse/ms)"], ["encvel", "encoder velocity"],
      ["err", "following error"], ["sts", "GT_GetSts"], ["homing", "homing status"], ["probe", "probe status 60B9h"]]) {
      kv.append(el("span", {}, label)); v[k] = el("span", {class: "v", "data-field": k}, "-"); kv.append(v[k]);
    }
    c.append(kv);
    c.append(el("div", {}, "6041h statusword"));
    const [swd, sw] = bitRow(lay.sw_bits, "sw"); c.append(swd);
    c.append(el("div", {}, "6040h controlword"));
    const [cwd, cw] = bitRow(lay.cw_bits, "cw"); c.append(cwd);
    c.append(el("div", {}, "GT status (table 6-2)"));
    const [gtd, gt] = bitRow(lay.status_bits, "gt"); c.append(gtd);
    const ctl = el("div", {class: "control-only"});
    const speed = el("input", {size: 5, value: "10", class: "jog-speed"});
    const minus = el("button", {class: "jog-minus"}, "Jog \u2212"), plus = el("button", {class: "jog-plus"}, "Jog +");
    const stop = el("button", {class: "stop"}, "Stop");
    const pos = el("input", {size: 8, value: "10000", class: "trap-pos"}), tv = el("input", {size: 5, value: "20", class: "trap-vel"});
    const ta = el("input", {size: 4, value: "0.5", class: "trap-acc"}), go = el("button", {class: "trap-go"}, "Trap move");
    ctl.append("jog ", speed, " pulse/ms ", minus, stop, plus, el("br"), "to ", pos, " at ", tv, " pulse/ms, acc ", ta, " ", go);
    c.append(ctl);
    const run = (p) => p.catch((e) => toast(String(e)));
    minus.onclick = () => run(ask("jog", a.axis, -Math.abs(+speed.value)));
    plus.onclick = () => run(ask("jog", a.axis, Math.abs(+speed.value)));
    stop.onclick = () => run(ask("stop", a.axis));
    go.onclick = () => run(ask("trap", a.axis, Math.round(+pos.value), +tv.value, +ta.value, +ta.value));
    root.append(c);
    S.axisCards[a.axis] = {v, sw, cw, gt, slave: a.slave, channel: a.channel || 0};
  }
}
function buildIo(lay) {
  const root = $("io-slaves"); root.innerHTML = ""; S.ioBits = [];
  for (const s of lay.slaves) {
    if (s.axis !== null) continue;
    const c = el("div", {class: "card", "data-slave": s.position});
    c.append(el("h3", {}, `Slave ${s.position}: ${s.name}`));
    for (const dir of ["in", "out"]) {
      for (const e of S.entries.filter((x) => x.slave === s.position && x.dir === dir)) {
        const line = el("div", {}, `${dir === "in" ? "input" : "output"} ${hex(e.index, 4)}:${hex(e.subindex, 2).slice(2)} ${e.name} `);
        const bits = el("div", {class: "bits"});
        for (let b = 0; b < Math.min(e.bits, 32); b++) {
          const sp = el("span", {class: "bit", title: `bit ${b}`, "data-dir": dir, "data-bit": b}, String(b));
          if (dir === "in" && lay.emulated) {
            sp.classList.add("field");
            sp.onclick = () => {
              if (!S.control) { toast("read-only panel: start it with --control to drive inputs"); return; }
              const cur = Number(entryValue(e).raw);
              ask("set_input", s.position, e.index, e.subindex, cur ^ (1 << b)).catch((x) => toast(String(x)));
            };
          }
          bits.append(sp); S.ioBits.push({e, b, sp});
        }
        line.append(bits); c.append(line);
      }
    }
    root.append(c);
  }
}

// --- every snapshot ---------------------------------------------------------------------------
function cia402(sw) {
  for (const [name, mask, value] of S.layout.states_402) if ((sw & mask) === value) return name;
  return "?";
}
function setBits(spans, word) { for (const [b, sp] of Object.entries(spans)) sp.classList.toggle("on", !!(word >> b & 1)); }
// a cell is written only when its text changes: a write of the same text still has the browser
// lay out, paint and raster again, 25 times a second (a page at rest cost Chromium a third of a
// CPU; now its clock and cycle count are all that change)
function put(e, text) { text = String(text); if (e.textContent !== text) e.textContent = text; }
const fmt = (x) => (x === null || x === undefined) ? "-" : (Number.isInteger(x) ? String(x) : x.toFixed(3));
function onSnap(s) {
  S.snap = s; S.snaps++;
  const h = s.image; const n = h.length >> 1;
  if (S.bytes.length !== n) S.bytes = new Uint8Array(n);
  for (let i = 0; i < n; i++) S.bytes[i] = parseInt(h.substr(2 * i, 2), 16);
  put($("time"), s.t_ms.toFixed(0)); put($("cycles"), s.cycles);
  S.wkcs.push(s.wkc); if (S.wkcs.length > 12) S.wkcs.shift();
  put($("wkc"), S.wkcs.join(" ")); put($("wkc-expected"), s.expected);
  put($("wkc-errors"), s.wkc_errors); put($("lost"), s.lost_frames);
  put($("bus-error"), s.error || "");
  const rows = $("slaves").tBodies[0].rows;
  for (let i = 0; i < rows.length; i++) {
    const st = AL[s.states[i]] || String(s.states[i]);
    const c = rows[i].cells[2]; put(c, st); c.classList.toggle("ok", st === "OP"); c.classList.toggle("bad", st !== "OP");
    put(rows[i].cells[3], s.codes[i] ? hex(s.codes[i], 4) : "0");
  }
  for (const e of S.entries) {
    const v = entryValue(e); e.last = v;
    put(e.valueCell, typeof v.value === "number" && !Number.isInteger(v.value) ? v.value.toPrecision(7) : v.value);
    put(e.rawCell, v.rawHex);
  }
  const f = s.axis_fields;
  for (const row of s.axes) {
    const a = Object.fromEntries(f.map((k, i) => [k, row[i]]));
    const card = S.axisCards[a.axis]; if (!card) continue;
    const val = (idx) => { const e = findEntry(card.slave, idx + 0x800 * card.channel, 0); return e ? Number(e.last.value) : null; };
    const sw = val(0x6041), cw = val(0x6040), m = val(0x6060), md = val(0x6061), pr = val(0x60B9);
    put(card.v.state, sw === null ? "-" : cia402(sw));
    const mn = (x) => x === null ? "-" : `${x} ${S.layout.mode_names[x] || ""}`.trim();
    put(card.v.mode, `${mn(m)} / ${mn(md)}`);
    put(card.v.prf, fmt(a.prf_pos)); put(card.v.enc, fmt(a.enc_pos));
    put(card.v.vel, fmt(a.prf_vel)); put(card.v.encvel, fmt(a.enc_vel));
    put(card.v.err, fmt(a.axis_error)); put(card.v.sts, hex(a.sts, 4));
    put(card.v.homing, a.homing === null ? "-" : ({0: "0 homing", 3: "3 homed", 5: "5 not homed / failed"}[a.homing] || a.homing));
    put(card.v.probe, pr === null ? "- (not mapped)" : hex(pr, 4));
    if (sw !== null) setBits(card.sw, sw);
    if (cw !== null) setBits(card.cw, cw);
    setBits(card.gt, a.sts);
  }
  for (const {e, b, sp} of S.ioBits) sp.classList.toggle("on", !!(Number(e.last.raw >> BigInt(b) & 1n)));
  if (s.log_lines !== S.logStart) refreshLog();
}
async function refreshLog() {
  const start = S.logStart; S.logStart = S.snap ? S.snap.log_lines : start;
  try {
    const r = await ask("log", start);
    const pre = $("log-lines");
    if (r.lines.length) { pre.textContent += (pre.textContent ? "\n" : "") + r.lines.join("\n"); pre.scrollTop = pre.scrollHeight; }
    const e = r.gt_errors[r.gt_errors.length - 1];
    $("gt-error").textContent = e ? `${e.function} returned ${e.code} at ${e.clock_ms} ms: ${e.reason}` : "none";
  } catch (x) { S.logStart = start; }
}

// --- the scope ------------------------------------------------------------------------------------
function buildScopePicks(lay) {
  const root = $("scope-picks"); root.innerHTML = "suggested: ";
  const sugg = [];
  for (const a of lay.axes) for (const k of ["prf", "enc", "err", "vel"]) sugg.push(`axis${a.axis}.${k}`);
  for (const s of lay.slaves) if (s.axis === null) for (const e of S.entries.filter((x) => x.slave === s.position))
    sugg.push(`${s.position}:${hex(e.index, 4)}:${e.subindex}`);
  for (const n of sugg) {
    const b = el("button", {class: "pick"}, n);
    b.onclick = () => { const f = $("scope-signals"); const cur = f.value.split(",").map((x) => x.trim()).filter(Boolean);
      if (!cur.includes(n)) cur.push(n); f.value = cur.join(","); };
    root.append(b);
  }
  if (!$("scope-signals").value && lay.axes.length) $("scope-signals").value = sugg.slice(0, 2).join(",");
}
function scopeBegin(names) {
  const sc = S.scope; sc.names = names; sc.rows = []; sc.running = true; sc.paused = false;
  const ts = $("trig-signal"); ts.innerHTML = "";
  names.forEach((n, i) => ts.append(el("option", {value: i + 1}, n)));
  const lg = $("scope-legend"); lg.innerHTML = "";
  names.forEach((n, i) => { const sw = el("span", {class: "swatch"}); sw.style.background = COLORS[i % COLORS.length]; lg.append(sw, n); });
}
function scopeWindowRows() {
  const sc = S.scope, rows = sc.rows; if (!rows.length) return [0, 0, 0, 0];
  const W = sc.window;
  let t1 = sc.paused && sc.frozen !== undefined ? sc.frozen : rows[rows.length - 1][0];
  const mode = $("trig-mode").value;
  if (mode !== "off") {
    const k = +$("trig-signal").value || 1, lvl = +$("trig-level").value;
    for (let i = rows.length - 1; i > 0; i--) {
      const a = rows[i - 1][k], b = rows[i][k];
      const hit = mode === "rising" ? a < lvl && b >= lvl : mode === "falling" ? a > lvl && b <= lvl : b >= lvl && a < lvl || (i === 1 && a >= lvl);
      if (hit && rows[rows.length - 1][0] >= rows[i][0] + 0.9 * W) { t1 = rows[i][0] + 0.9 * W; break; }
      if (hit) { t1 = rows[i][0] + 0.9 * W; break; }
    }
  }
  const t0 = t1 - W;
  let lo = 0, hi = rows.length;
  while (lo < hi) { const m = (lo + hi) >> 1; if (rows[m][0] < t0) lo = m + 1; else hi = m; }
  let end = lo; while (end < rows.length && rows[end][0] <= t1) end++;
  return [lo, end, t0, t1];
}
let scopeDrawn = "";
function drawScope() {
  requestAnimationFrame(drawScope);
  const cv = $("scope-canvas"), sc = S.scope, rows = sc.rows;
  // drawn again only when what it shows may have changed (new samples, a control, the size):
  // a page left open costs its browser nothing between samples
  const key = [sc.names.join(), rows.length, rows.length ? rows[rows.length - 1][0] : "", sc.paused,
    sc.frozen, sc.window, $("trig-mode").value, $("trig-signal").value, $("trig-level").value,
    cv.width, cv.height].join("|");
  if (key === scopeDrawn) return;
  scopeDrawn = key;
  const g = cv.getContext("2d");
  g.fillStyle = "#fff"; g.fillRect(0, 0, cv.width, cv.height);
  const [lo, end, t0, t1] = scopeWindowRows();
  $("scope-info").textContent = `${sc.rows.length} samples` + (sc.paused ? " (paused)" : "");
  if (end <= lo) return;
  const W = cv.width - 60, H = cv.height - 20, L = 55;
  let ymin = Infinity, ymax = -Infinity;
  for (let i = lo; i < end; i++) for (let k = 1; k <= sc.names.length; k++) { const v = sc.rows[i][k]; if (v < ymin) ymin = v; if (v > ymax) ymax = v; }
  if (ymin === ymax) { ymin -= 1; ymax += 1; }
  const y = (v) => 5 + H - (v - ymin) / (ymax - ymin) * H, x = (t) => L + (t - t0) / (t1 - t0) * W;
  g.strokeStyle = "#ddd"; g.fillStyle = "#555"; g.font = "11px sans-serif";
  for (let j = 0; j <= 4; j++) { const v = ymin + (ymax - ymin) * j / 4; g.beginPath(); g.moveTo(L, y(v)); g.lineTo(L + W, y(v)); g.stroke(); g.fillText(v.toPrecision(5), 2, y(v) + 4); }
  g.fillText(`${t0.toFixed(0)} ms`, L, cv.height - 2); g.fillText(`${t1.toFixed(0)} ms`, L + W - 60, cv.height - 2);
  // decimated for display only: min and max of every pixel column
  for (let k = 1; k <= sc.names.length; k++) {
    g.strokeStyle = COLORS[(k - 1) % COLORS.length]; g.beginPath();
    let col = -1, mn = 0, mx = 0, first = true;
    const flush = () => { if (col < 0) return; if (first) { g.moveTo(col, y(mn)); first = false; } else g.lineTo(col, y(mn)); g.lineTo(col, y(mx)); };
    for (let i = lo; i < end; i++) {
      const c = Math.round(x(sc.rows[i][0])), v = sc.rows[i][k];
      if (c !== col) { flush(); col = c; mn = mx = v; } else { if (v < mn) mn = v; if (v > mx) mx = v; }
    }
    flush(); g.stroke();
  }
}
S.scopeCsv = () => {  // every sample the recorder took, full precision
  const sc = S.scope;
  return ["time_ms," + sc.names.join(","), ...sc.rows.map((r) => r.map(String).join(","))].join("\n") + "\n";
};
function download(name, href) { const a = el("a", {href, download: name}); document.body.append(a); a.click(); a.remove(); }

// --- object dictionary ---------------------------------------------------------------------------
async function loadOd() {
  const slave = +$("od-slave").value;
  $("od-msg").textContent = "reading...";
  try { S.odRows = await ask("sdos", slave, true, null); $("od-msg").textContent = `${S.odRows.length} entries`; }
  catch (e) { $("od-msg").textContent = String(e); S.odRows = []; }
  renderOd();
}
function renderOd() {
  const tb = $("od-table").tBodies[0]; tb.innerHTML = "";
  const f = $("od-filter").value.toLowerCase();
  for (const r of S.odRows) {
    if (f && !r.name.toLowerCase().includes(f)) continue;
    const tr = el("tr"); const vc = el("td", {class: "num"}, r.value === null ? "" : String(r.value));
    const up = el("button", {}, "Upload");
    up.onclick = async () => {
      try { const x = await ask("sdo_upload", r.position, r.index, r.subindex); vc.textContent = `${x.bytes} (hex)`; }
      catch (e) { vc.textContent = String(e); }
    };
    tr.append(el("td", {class: "mono"}, `${hex(r.index, 4)}:${hex(r.subindex, 2).slice(2)}`), el("td", {}, r.name),
      el("td", {}, r.type), el("td", {}, r.access), el("td", {}, r.pdo), vc, el("td", {}, "")); tr.cells[6].append(up);
    tr.onclick = (ev) => { if (ev.target.tagName !== "BUTTON") { $("od-index").value = hex(r.index, 4); $("od-sub").value = r.subindex; $("od-type").value = r.type; } };
    tb.append(tr);
  }
}

// --- wiring -----------------------------------------------------------------------------------
function connect() {
  const proto = location.protocol === "https:" ? "wss:" : "ws:";
  ws = new WebSocket(`${proto}//${location.host}/ws${location.search}`);
  ws.onopen = async () => {
    $("conn").textContent = "live"; S.connected = true;
    try { buildLayout(await ask("layout")); S.ready = true; } catch (e) { toast(String(e)); }
  };
  ws.onclose = () => { $("conn").textContent = "disconnected"; S.connected = false; };
  ws.onmessage = (m) => {
    const msg = JSON.parse(m.data);
    if (msg.type === "reply") {
      const w = waiting[msg.id]; delete waiting[msg.id];
      if (w) msg.ok ? w.resolve(msg.result) : w.reject(msg.error);
    } else if (msg.type === "snap") { if (S.layout) onSnap(msg); }
    else if (msg.type === "hello") {
      S.control = msg.control; document.body.classList.toggle("control", msg.control);
      $("mode").textContent = msg.control ? "control" : "read-only"; $("title").textContent = msg.title;
      if (msg.scope) scopeBegin(msg.scope.names);
    } else if (msg.type === "scope_start") scopeBegin(msg.names);
    else if (msg.type === "scope") { for (const r of msg.rows) S.scope.rows.push(r); }
    else if (msg.type === "scope_stop") S.scope.running = false;
    else if (msg.type === "gone") { $("conn").textContent = "the application has ended"; toast(msg.error); }
  };
}
$("scope-start").onclick = () => ask("scope_start", $("scope-signals").value.split(",").map((x) => x.trim()).filter(Boolean)).catch((e) => toast(String(e)));
$("scope-stop").onclick = () => ask("scope_stop").catch((e) => toast(String(e)));
$("scope-pause").onclick = () => { const sc = S.scope; sc.paused = !sc.paused; sc.frozen = sc.rows.length ? sc.rows[sc.rows.length - 1][0] : 0;
  $("scope-pause").textContent = sc.paused ? "Resume" : "Pause"; };
$("scope-window").onchange = () => { S.scope.window = +$("scope-window").value; };
$("scope-zoom-in").onclick = () => { S.scope.window = Math.max(5, S.scope.window / 2); };
$("scope-zoom-out").onclick = () => { S.scope.window *= 2; };
$("scope-csv").onclick = () => download("gtecat-scope.csv", URL.createObjectURL(new Blob([S.scopeCsv()], {type: "text/csv"})));
$("scope-png").onclick = () => download("gtecat-scope.png", $("scope-canvas").toDataURL("image/png"));
$("od-load").onclick = loadOd;
$("od-filter").oninput = renderOd;
$("od-write").onclick = async () => {
  try {
    await ask("sdo_write", +$("od-slave").value, parseInt($("od-index").value), parseInt($("od-sub").value || "0"), $("od-value").value, $("od-type").value);
    $("od-msg").textContent = "written";
  } catch (e) { $("od-msg").textContent = String(e); }
};
// faults: "KIND key=value ..." as the command line takes it (gtecat fault inject)
function faultSpec(text) {
  const words = text.trim().split(/\s+/).filter(Boolean);
  const spec = {kind: words.shift() || ""};
  for (const w of words) {
    const i = w.indexOf("=");
    if (i <= 0) throw new Error(`${w}: expected key=value`);
    const v = w.slice(i + 1);
    spec[w.slice(0, i)] = v.includes(",") ? v.split(",") : v;
  }
  return spec;
}
async function listFaults() {
  try {
    const rows = await ask("fault_list");
    const body = $("fault-table").querySelector("tbody");
    body.replaceChildren(...rows.map((f) => { const tr = el("tr");
      tr.append(el("td", {}, String(f.id)), el("td", {}, f.state), el("td", {}, f.describe)); return tr; }));
    if (!rows.length) $("fault-msg").textContent = "no fault armed or active";
  } catch (e) { $("fault-msg").textContent = String(e); }
}
$("fault-list").onclick = listFaults;
$("fault-inject").onclick = async () => {
  try { const f = await ask("fault_inject", faultSpec($("fault-spec").value));
    $("fault-msg").textContent = `fault ${f.id}: ${f.describe} (${f.state})`; listFaults();
  } catch (e) { $("fault-msg").textContent = String(e); }
};
$("fault-clear").onclick = async () => {
  try { await ask("fault_clear"); listFaults(); } catch (e) { $("fault-msg").textContent = String(e); }
};
setInterval(() => { const now = performance.now(); if (S.rateT0) $("rate").textContent = (S.snaps * 1000 / (now - S.rateT0)).toFixed(1);
  S.rateT0 = now; S.snaps = 0; }, 1000);
connect();
requestAnimationFrame(drawScope);
})();
