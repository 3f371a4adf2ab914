// cellstress's 3D view of a cell and an episode, drawn with plotly.js (inlined before this script).
// It reads the JSON in #cs3d-data (report/scene3d.py: the simulator's own geometry, lengths in mm) and keeps its
// state in #cs3d's data attributes (data-ready, data-step, data-marker), which the tests read. Text from files
// (names) is only ever set with textContent, never handed to plotly (which renders a subset of HTML).
(function () {
  "use strict";
  var root = document.getElementById("cs3d");
  if (!root || typeof Plotly === "undefined") { return; }
  var DATA = JSON.parse(document.getElementById("cs3d-data").textContent);
  var CELL = DATA.cell, REACH = DATA.reach;
  var gd = document.getElementById("cs3d-plot");
  var slider = document.getElementById("cs3d-step");
  var info = document.getElementById("cs3d-info");
  var playBtn = document.getElementById("cs3d-play");
  var pick = document.getElementById("cs3d-episode");
  var legend = document.getElementById("cs3d-legend");
  var COL = {
    floor: "#ececec", fence: "#2b2b2b", pallet: "#a0785a", table: "#dcc9a0", obstacle: "#c9c3b8",
    pedestal: "#9e9e9e", robot: "#6e6e6e", hit: "#d62728", body: "#1f77b4", touch: "#e8590c", reach: "#ffb347",
    path: "#1f77b4", start: "#2ca02c", contact: "#ff00ff"
  };
  var NA = 10, NL = 3, PER = 2 + 2 * NL * NA, FACES = 4 * NL * NA;  // capsule mesh: vertices, faces each
  var MM = 0.001;
  var FIELD_IDLE = 0.12, FIELD_ACTIVE = 0.5;

  function range(n) { var out = []; for (var i = 0; i < n; i++) { out.push(i); } return out; }

  // ---- capsules as meshes: topology once, vertices per step ----------------------------------------------
  function capsuleFaces(count) {
    var I = [], J = [], K = [];
    for (var c = 0; c < count; c++) {
      var o = c * PER, last = o + 1 + (2 * NL - 1) * NA;
      for (var j = 0; j < NA; j++) {
        var j1 = (j + 1) % NA;
        I.push(o); J.push(o + 1 + j1); K.push(o + 1 + j);
        for (var r = 0; r < 2 * NL - 1; r++) {
          var r0 = o + 1 + r * NA, r1 = r0 + NA;
          I.push(r0 + j); J.push(r0 + j1); K.push(r1 + j);
          I.push(r0 + j1); J.push(r1 + j1); K.push(r1 + j);
        }
        I.push(last + j); J.push(last + j1); K.push(o + PER - 1);
      }
    }
    return [I, J, K];
  }

  function norm(v) { var l = Math.hypot(v[0], v[1], v[2]); return l > 1e-12 ? [v[0] / l, v[1] / l, v[2] / l] : null; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }

  function capsuleVertices(ab, radii) {  // ab: per capsule ax ay az bx by bz [mm]
    var X = [], Y = [], Z = [];
    for (var c = 0; c < radii.length; c++) {
      var a = [ab[6 * c] * MM, ab[6 * c + 1] * MM, ab[6 * c + 2] * MM];
      var b = [ab[6 * c + 3] * MM, ab[6 * c + 4] * MM, ab[6 * c + 5] * MM];
      var r = radii[c] * MM;
      var d = norm([b[0] - a[0], b[1] - a[1], b[2] - a[2]]) || [0, 0, 1];
      var u = norm(cross(d, Math.abs(d[2]) < 0.9 ? [0, 0, 1] : [1, 0, 0]));
      var w = cross(d, u);
      var put = function (p, s, dr, rr) {
        for (var j = 0; j < NA; j++) {
          var th = 2 * Math.PI * j / NA, cu = Math.cos(th) * rr, sw = Math.sin(th) * rr;
          X.push(p[0] + s * dr * d[0] + cu * u[0] + sw * w[0]);
          Y.push(p[1] + s * dr * d[1] + cu * u[1] + sw * w[1]);
          Z.push(p[2] + s * dr * d[2] + cu * u[2] + sw * w[2]);
        }
      };
      X.push(a[0] - r * d[0]); Y.push(a[1] - r * d[1]); Z.push(a[2] - r * d[2]);
      for (var k = 1; k <= NL; k++) { var ph = k * Math.PI / 2 / NL; put(a, -1, r * Math.cos(ph), r * Math.sin(ph)); }
      for (k = NL; k >= 1; k--) { ph = k * Math.PI / 2 / NL; put(b, 1, r * Math.cos(ph), r * Math.sin(ph)); }
      X.push(b[0] + r * d[0]); Y.push(b[1] + r * d[1]); Z.push(b[2] + r * d[2]);
    }
    return [X, Y, Z];
  }

  function faceColors(count, hit, base, hot) {
    var out = [];
    for (var c = 0; c < count; c++) { for (var f = 0; f < FACES; f++) { out.push(c === hit ? hot : base); } }
    return out;
  }

  // ---- the cell: prisms, panels, fields ------------------------------------------------------------------
  function Mesh() { this.x = []; this.y = []; this.z = []; this.i = []; this.j = []; this.k = []; this.fc = []; }
  Mesh.prototype.vert = function (x, y, z) { this.x.push(x * MM); this.y.push(y * MM); this.z.push(z * MM); return this.x.length - 1; };
  Mesh.prototype.tri = function (a, b, c, color) { this.i.push(a); this.j.push(b); this.k.push(c); this.fc.push(color); };
  Mesh.prototype.prism = function (poly, tris, z0, z1, color) {
    var n = poly.length, lo = [], hi = [], t, q;
    for (q = 0; q < n; q++) { lo.push(this.vert(poly[q][0], poly[q][1], z0)); hi.push(this.vert(poly[q][0], poly[q][1], z1)); }
    for (t = 0; t < tris.length; t++) {
      this.tri(hi[tris[t][0]], hi[tris[t][1]], hi[tris[t][2]], color);
      if (z0 > 0) { this.tri(lo[tris[t][0]], lo[tris[t][2]], lo[tris[t][1]], color); }
    }
    for (q = 0; q < n; q++) {
      var q1 = (q + 1) % n;
      this.tri(lo[q], lo[q1], hi[q1], color); this.tri(lo[q], hi[q1], hi[q], color);
    }
  };
  Mesh.prototype.panel = function (rc, color) {  // x0 y0 x1 y1 bottom top
    var a = this.vert(rc[0], rc[1], rc[4]), b = this.vert(rc[2], rc[3], rc[4]);
    var c = this.vert(rc[2], rc[3], rc[5]), d = this.vert(rc[0], rc[1], rc[5]);
    this.tri(a, b, c, color); this.tri(a, c, d, color);
  };
  Mesh.prototype.trace = function (extra) {
    var t = {type: "mesh3d", x: this.x, y: this.y, z: this.z, i: this.i, j: this.j, k: this.k, facecolor: this.fc,
             flatshading: true, hoverinfo: "skip", showscale: false, lighting: {ambient: 0.7, diffuse: 0.5}};
    for (var key in extra) { t[key] = extra[key]; }
    return t;
  };

  function lines(segments, color, width, extra) {  // segments: [[p0, p1], ...] in mm
    var x = [], y = [], z = [];
    segments.forEach(function (s) {
      x.push(s[0][0] * MM, s[1][0] * MM, null); y.push(s[0][1] * MM, s[1][1] * MM, null);
      z.push(s[0][2] * MM, s[1][2] * MM, null);
    });
    var t = {type: "scatter3d", mode: "lines", x: x, y: y, z: z, line: {color: color, width: width},
             hoverinfo: "skip", showlegend: false};
    for (var key in extra) { t[key] = extra[key]; }
    return t;
  }

  function fieldTrace(f) {
    var m = new Mesh();
    if (f.shape === "prism") { m.prism(f.poly, f.tris, f.z[0], Math.max(f.z[1], 10), f.color); }
    else { m.panel(f.rect, f.color); }
    return m.trace({opacity: f.speed === 0 ? FIELD_IDLE : FIELD_IDLE * 0.7});
  }

  // ---- the figure ---------------------------------------------------------------------------------------
  var traces = [], idx = {}, episode = null, step = 0, timer = null;

  function staticTraces() {
    var fl = CELL.floor, floor = new Mesh();
    var a = floor.vert(fl[0], fl[2], 0), b = floor.vert(fl[1], fl[2], 0), c = floor.vert(fl[1], fl[3], 0);
    var d = floor.vert(fl[0], fl[3], 0);
    floor.tri(a, b, c, COL.floor); floor.tri(a, c, d, COL.floor);
    traces.push(floor.trace({lighting: {ambient: 1.0, diffuse: 0.0}}));
    var solids = new Mesh();
    CELL.prisms.forEach(function (p) { solids.prism(p.poly, p.tris, p.z[0], p.z[1], COL[p.kind]); });
    if (solids.i.length) { traces.push(solids.trace({})); }
    var panels = new Mesh(), edges = [];
    CELL.panels.forEach(function (p) {
      if (p.kind === "door") { return; }  // a door's leaf is drawn as its device's field (it turns active)
      panels.panel(p.rect, p.kind === "pallet" ? COL.pallet : COL.fence);
      var r = p.rect;
      edges.push([[r[0], r[1], r[4]], [r[2], r[3], r[4]]], [[r[0], r[1], r[5]], [r[2], r[3], r[5]]],
                 [[r[0], r[1], r[4]], [r[0], r[1], r[5]]], [[r[2], r[3], r[4]], [r[2], r[3], r[5]]]);
    });
    if (panels.i.length) { traces.push(panels.trace({opacity: 0.45})); traces.push(lines(edges, COL.fence, 4)); }
    idx.fields = [];
    CELL.fields.forEach(function (f) {
      idx.fields.push(traces.length);
      traces.push(fieldTrace(f));
    });
    var arrows = [];
    CELL.starts.forEach(function (s) {
      var h = s.heading * Math.PI / 180, L = 300;
      var p = [s.xy[0], s.xy[1], 5], q = [s.xy[0] + L * Math.cos(h), s.xy[1] + L * Math.sin(h), 5];
      arrows.push([p, q]);
      arrows.push([q, [q[0] - 90 * Math.cos(h - 0.5), q[1] - 90 * Math.sin(h - 0.5), 5]]);
      arrows.push([q, [q[0] - 90 * Math.cos(h + 0.5), q[1] - 90 * Math.sin(h + 0.5), 5]]);
    });
    traces.push(lines(arrows, COL.start, 6));
  }

  function episodeTraces(ep) {
    traces.length = idx.base;
    if (ep.path.length) {
      traces.push({type: "scatter3d", mode: "lines+markers", x: ep.path.map(function (p) { return p[0] * MM; }),
                   y: ep.path.map(function (p) { return p[1] * MM; }), z: ep.path.map(function () { return 0.01; }),
                   line: {color: COL.path, width: 3}, marker: {size: 2, color: COL.path}, hoverinfo: "skip"});
    }
    idx.robot = traces.length;
    var f = capsuleFaces(CELL.link_r.length);
    traces.push({type: "mesh3d", x: [], y: [], z: [], i: f[0], j: f[1], k: f[2], facecolor: [], flatshading: false,
                 hoverinfo: "skip", lighting: {ambient: 0.55, diffuse: 0.7, specular: 0.2}});
    idx.body = -1; idx.reach = []; idx.marker = -1;
    if (ep.body) {
      idx.body = traces.length;
      f = capsuleFaces(ep.body_r.length);
      traces.push({type: "mesh3d", x: [], y: [], z: [], i: f[0], j: f[1], k: f[2], facecolor: [], flatshading: false,
                   hoverinfo: "skip", lighting: {ambient: 0.55, diffuse: 0.7, specular: 0.2}});
    }
    if (ep.keep && REACH) {
      [0, 1].forEach(function () {
        idx.reach.push(traces.length);
        traces.push({type: "scatter3d", mode: "markers", x: [], y: [], z: [], hoverinfo: "skip",
                     marker: {size: 2, color: COL.reach, opacity: 0.2}});
      });
    }
    if (ep.marker) {
      idx.marker = traces.length;
      traces.push({type: "scatter3d", mode: "lines+markers", x: [], y: [], z: [], hoverinfo: "skip",
                   line: {color: "#000000", width: 6},
                   marker: {size: [14, 7], color: [COL.contact, COL.body], symbol: ["diamond", "circle"],
                            line: {color: "#000000", width: 1}}});
    }
  }

  function decodeBits(text) {
    var raw = atob(text), out = new Uint8Array(raw.length);
    for (var i = 0; i < raw.length; i++) { out[i] = raw.charCodeAt(i); }
    return out;
  }

  function reachPoints(ep, i, side) {
    var nodes = REACH.nodes, s = ep.sh[i], R = ep.trunk[i], mask = ep.keep[i][side];
    var bits = mask === null ? null : decodeBits(mask);
    var X = [], Y = [], Z = [], sg = side === 0 ? -1 : 1;  // the left arm is the right one mirrored
    for (var n = 0; n < nodes.length; n++) {
      if (bits !== null && !((bits[n >> 3] >> (n & 7)) & 1)) { continue; }
      var l0 = nodes[n][0] * MM, l1 = sg * nodes[n][1] * MM, l2 = nodes[n][2] * MM;
      var sx = side * 3;
      X.push(s[sx] * MM + R[0] * l0 + R[1] * l1 + R[2] * l2);
      Y.push(s[sx + 1] * MM + R[3] * l0 + R[4] * l1 + R[5] * l2);
      Z.push(s[sx + 2] * MM + R[6] * l0 + R[7] * l1 + R[8] * l2);
    }
    return [X, Y, Z];
  }

  function fmt(v, nd) { return v === null || v === undefined ? "-" : v.toFixed(nd); }

  function setStep(i) {
    var ep = episode, m = ep.marker, atKey = m !== null && i === m.step;
    step = i;
    slider.value = String(i);
    var ids = [idx.robot], X = [], Y = [], Z = [];
    var v = capsuleVertices(ep.robot[i], CELL.link_r);
    X.push(v[0]); Y.push(v[1]); Z.push(v[2]);
    var colors = {facecolor: [faceColors(CELL.link_r.length, atKey ? m.link : -1, COL.robot, COL.hit)]};
    var cids = [idx.robot];
    if (idx.body >= 0) {
      v = capsuleVertices(ep.body[i], ep.body_r);
      ids.push(idx.body); X.push(v[0]); Y.push(v[1]); Z.push(v[2]);
      colors.facecolor.push(faceColors(ep.body_r.length, atKey ? m.part : -1, COL.body, COL.touch));
      cids.push(idx.body);
    }
    idx.reach.forEach(function (t, side) {
      var p = reachPoints(ep, i, side);
      ids.push(t); X.push(p[0]); Y.push(p[1]); Z.push(p[2]);
    });
    if (idx.marker >= 0) {
      ids.push(idx.marker);
      X.push(atKey ? [m.rp[0] * MM, m.hp[0] * MM] : []);
      Y.push(atKey ? [m.rp[1] * MM, m.hp[1] * MM] : []);
      Z.push(atKey ? [m.rp[2] * MM, m.hp[2] * MM] : []);
    }
    var active = CELL.fields.map(function (f) {
      var s = ep.first_seen[f.name];
      return s !== undefined && i >= s;
    });
    var reachColor = idx.reach.map(function (t, side) { return atKey && m.reach === side ? COL.touch : COL.reach; });
    var row = ep.rows[i];
    var text = "t = " + fmt(row.t, 2) + " s";
    if (ep.body) {
      text += "   d_HR = " + fmt(row.d, 3) + " m   v_R = " + fmt(row.v, 2) + " m/s   robot: " + row.phase +
        "   seen by: " + (row.seen.length ? row.seen.join(", ") : "-");
      if (atKey) { text += "   " + (m.kind === "contact" ? "CONTACT: " : "closest call: ") + m.text; }
    } else {
      text += " of the robot's cycle (step " + i + " of " + (ep.n - 1) + ")";
    }
    info.textContent = text;
    root.setAttribute("data-step", String(i));
    root.setAttribute("data-marker", atKey ? m.kind : "");
    root.setAttribute("data-active", CELL.fields.filter(function (f, k) { return active[k]; })
      .map(function (f) { return f.name; }).join(","));
    Array.prototype.forEach.call(legend.querySelectorAll("li[data-field]"), function (li) {
      li.className = active[Number(li.getAttribute("data-field"))] ? "active" : "";
    });
    var work = Plotly.restyle(gd, {x: X, y: Y, z: Z}, ids)
      .then(function () { return Plotly.restyle(gd, colors, cids); });
    if (idx.reach.length) {
      work = work.then(function () {
        return Plotly.restyle(gd, {"marker.color": reachColor, "marker.opacity": reachColor.map(function (c) {
          return c === COL.touch ? 0.45 : 0.2;
        })}, idx.reach);
      });
    }
    if (idx.fields.length) {
      work = work.then(function () {
        return Plotly.restyle(gd, {opacity: CELL.fields.map(function (f, k) {
          return active[k] ? FIELD_ACTIVE : (f.speed === 0 ? FIELD_IDLE : FIELD_IDLE * 0.7);
        })}, idx.fields);
      });
    }
    root.csPending = work;  // the tests wait on it (and then on a frame) before a screenshot
    return work;
  }

  function stop() {
    if (timer !== null) { clearTimeout(timer); timer = null; }
    playBtn.textContent = "play";
  }

  function tick() {
    timer = setTimeout(function () {
      if (step >= episode.n - 1) { stop(); return; }
      setStep(step + 1).then(function () { if (timer !== null) { tick(); } });
    }, episode.dt * 1000);
  }

  function bounds() {
    var fl = CELL.floor, top = 2000;
    DATA.episodes.forEach(function (ep) {
      ep.robot.forEach(function (ab) { for (var q = 2; q < ab.length; q += 3) { top = Math.max(top, ab[q] + 150); } });
    });
    CELL.panels.forEach(function (p) { top = Math.max(top, p.rect[5]); });
    return {x: [fl[0] * MM - 0.1, fl[1] * MM + 0.1], y: [fl[2] * MM - 0.1, fl[3] * MM + 0.1], z: [0, top * MM + 0.1]};
  }

  var VIEWS = {
    iso: {eye: {x: 1.1, y: -1.5, z: 1.0}, up: {x: 0, y: 0, z: 1}, projection: {type: "perspective"}},
    top: {eye: {x: 0, y: 0, z: 2.2}, up: {x: 0, y: 1, z: 0}, projection: {type: "orthographic"}},
    front: {eye: {x: 0, y: 2.2, z: 0.25}, up: {x: 0, y: 0, z: 1}, projection: {type: "orthographic"}},
    side: {eye: {x: 2.2, y: 0, z: 0.25}, up: {x: 0, y: 0, z: 1}, projection: {type: "orthographic"}}
  };

  function legendItem(color, label, field) {
    var li = document.createElement("li"), sw = document.createElement("span");
    sw.className = "sw"; sw.style.background = color;
    li.appendChild(sw); li.appendChild(document.createTextNode(label));
    if (field !== undefined) { li.setAttribute("data-field", String(field)); }
    legend.appendChild(li);
  }

  function fillLegend(ep) {
    legend.textContent = "";
    legend.className = "cs3d-legend";
    legendItem(COL.robot, "robot collision capsules");
    if (ep.marker) { legendItem(COL.hit, "robot link touching at the " + ep.marker.kind + " step"); }
    if (ep.body) {
      legendItem(COL.body, "worker's body capsules" + (idx.reach.length ? "" : " and arms"));
      if (idx.reach.length) { legendItem(COL.reach, "arms' reach volumes (nodes of the reach field)"); }
      legendItem(COL.touch, "the touching body part at the " + (ep.marker ? ep.marker.kind : "") + " step");
      legendItem(COL.path, "worker's path");
      legendItem(COL.contact, ep.marker && ep.marker.kind === "contact" ? "contact point (slider at the hazard's step)"
        : "closest point (slider at the closest call)");
    }
    legendItem(COL.fence, "fence panels (true bottom and top)");
    var kinds = {};
    CELL.prisms.forEach(function (p) { kinds[p.kind] = true; });
    Object.keys(kinds).sort().forEach(function (k) { legendItem(COL[k], k + " (prism, its height)"); });
    CELL.fields.forEach(function (f, k) {
      var what = f.shape === "prism" ? "field up to its plane" : (f.shape === "door" ? "door leaf" : "vertical field");
      legendItem(f.color, f.name + " (" + f.type + ", " + what + (ep.body ? "; bright once it sees the worker)" : ")"), k);
    });
    legendItem(COL.start, "start points and headings");
  }

  function load(e) {
    stop();
    episode = DATA.episodes[e];
    episodeTraces(episode);
    slider.max = String(episode.n - 1);
    fillLegend(episode);
    var b = bounds();
    var axis = function (title, r) {
      return {title: {text: title}, range: r, autorange: false, backgroundcolor: "#ffffff", gridcolor: "#dddddd",
              zeroline: false, showspikes: false};
    };
    var layout = {
      margin: {l: 0, r: 0, t: 0, b: 0}, showlegend: false, paper_bgcolor: "#ffffff", uirevision: "cs3d",
      scene: {xaxis: axis("x [m]", b.x), yaxis: axis("y [m]", b.y), zaxis: axis("z [m]", b.z), aspectmode: "data",
              camera: VIEWS.iso, dragmode: "orbit"}
    };
    var config = {displaylogo: false, responsive: true, scrollZoom: true, showLink: false, showSendToCloud: false,
                  showEditInChartStudio: false, typesetMath: false,
                  modeBarButtonsToRemove: ["toImage", "resetCameraLastSave3d"]};
    root.setAttribute("data-ready", "0");
    return Plotly.newPlot(gd, traces, layout, config).then(function () {
      return setStep(0);
    }).then(function () { root.setAttribute("data-ready", "1"); });
  }

  staticTraces();
  idx.base = traces.length;
  slider.addEventListener("input", function () { stop(); setStep(Number(slider.value)); });
  playBtn.addEventListener("click", function () {
    if (timer !== null) { stop(); return; }
    if (step >= episode.n - 1) { setStep(0); }
    playBtn.textContent = "pause";
    tick();
  });
  Array.prototype.forEach.call(root.querySelectorAll("button[data-view]"), function (btn) {
    btn.addEventListener("click", function () {
      Plotly.relayout(gd, {"scene.camera": VIEWS[btn.getAttribute("data-view")]});
    });
  });
  if (pick) { pick.addEventListener("change", function () { load(Number(pick.value)); }); }
  root.csStep = setStep;  // for the tests and the console: returns a promise
  load(0);
})();
