/* kinlib configuration picker (kinlib/widgets/picker.js), problem 4.1: a button per named configuration; the arm
   (drawn by core.js, window.kinlibFront) with each joint's velocity arrow at the tool (column i of J_ṗ, θ̇_i = 1),
   a bar chart of the chosen row's contributions J[row, i] and a table naming the largest. Everything from the
   generated skel(q) and jg(q): no kernel. Called as kinlibPicker(element, spec). */
(function () {
  "use strict";
  var F = window.kinlibFront, el = F.el, svg = F.svg, C = F.C, fmt = F.fmt;
  var DASH = ["", "7 3", "2 3", "9 3 2 3", "4 4", "1 2"]; // joints told apart without colour too

  function sign(x) { return (x >= 0 ? "+" : "") + x.toFixed(4); }
  // the joint(s) with the largest |value| (ties within 1e-9 relative), as kinlib.manipulability.strongest_joints
  function strongest(c) {
    var a = c.map(Math.abs), top = Math.max.apply(null, a), out = [];
    a.forEach(function (m, i) { if (Math.abs(m - top) <= 1e-9 * Math.max(top, 1e-300)) out.push(i + 1); });
    return out;
  }
  function arrowHead(tip, u, g, color) {
    var hw = 5;
    svg("path", {d: "M" + tip[0] + " " + tip[1] + " L" + (tip[0] - 1.6 * hw * u[0] + hw * u[1]) + " " + (tip[1] - 1.6 * hw * u[1] - hw * u[0]) +
      " L" + (tip[0] - 1.6 * hw * u[0] - hw * u[1]) + " " + (tip[1] - 1.6 * hw * u[1] + hw * u[0]) + " Z", fill: color}, g);
  }

  function drawArrows(X, st) {
    var S = X.S, n = S.n, J = st.J, tool = st.pts[st.pts.length - 1], P = function (p) { return F.project(S, X.view, p); };
    var ts = P(tool), g = svg("g", {class: "kinlib-jvels"}, X.g);
    for (var i = 0; i < n; i++) {
      var v = [J[3 * n + i], J[4 * n + i], S.planar ? 0 : J[5 * n + i]];
      var tip = [tool[0] + S.scale * v[0], tool[1] + S.scale * v[1], tool[2] + S.scale * v[2]], tp = P(tip);
      var dx = tp[0] - ts[0], dy = tp[1] - ts[1], len = Math.hypot(dx, dy);
      var a = svg("path", {d: F.pathOf([ts, tp]), stroke: S.colors[i], "stroke-width": 2.5, "stroke-dasharray": DASH[i % DASH.length] || null,
        class: "kinlib-jvel", "data-joint": i + 1}, g);
      a.setAttribute("data-x", v[0]); a.setAttribute("data-y", v[1]); a.setAttribute("data-z", v[2]);
      if (len > 2) {
        arrowHead(tp, [dx / len, dy / len], g, S.colors[i]);
        svg("text", {x: tp[0] + 6 * dx / len + 2, y: tp[1] + 6 * dy / len + 4, "font-size": 12, fill: S.colors[i], "font-weight": "bold"}, g).textContent = "θ̇" + (i + 1);
      }
    }
  }

  // the bar chart: J[row, i] per joint on one scale for every configuration
  function bars(X, c, row, name) {
    var S = X.S, W = 300, H = 220, l = 40, r = 8, t = 30, b = 24, n = S.n, box = X.chart;
    while (box.firstChild) box.removeChild(box.firstChild);
    var sy = function (v) { return t + (H - t - b) * (1 - (v + 1.2 * S.top) / (2.4 * S.top)); }, bw = (W - l - r) / n;
    svg("text", {x: W / 2, y: 12, "font-size": 11, "text-anchor": "middle", fill: "#333"}, box).textContent = name;
    svg("text", {x: W / 2, y: 25, "font-size": 11, "text-anchor": "middle", fill: "#333"}, box).textContent = S.rowNames[row] + " for each θ̇_i = 1";
    [-S.top, 0, S.top].forEach(function (v) {
      svg("path", {d: F.pathOf([[l, sy(v)], [W - r, sy(v)]]), stroke: v === 0 ? "#111" : C.grid}, box);
      svg("text", {x: l - 4, y: sy(v) + 4, "font-size": 10, "text-anchor": "end", fill: "#555"}, box).textContent = fmt(v, 3);
    });
    c.forEach(function (v, i) {
      var x = l + bw * i + bw * 0.2, y0 = sy(0), y1 = sy(v);
      svg("rect", {x: x, y: Math.min(y0, y1), width: bw * 0.6, height: Math.abs(y1 - y0), fill: S.colors[i], stroke: "#111", "stroke-width": 1,
        "stroke-dasharray": DASH[i % DASH.length] || null, class: "kinlib-bar", "data-joint": i + 1, "data-value": v}, box);
      svg("text", {x: x + bw * 0.3, y: v >= 0 ? y1 - 3 : y1 + 12, "font-size": 10, "text-anchor": "middle", fill: "#111"}, box).textContent = sign(v);
      svg("text", {x: x + bw * 0.3, y: H - 6, "font-size": 11, "text-anchor": "middle", fill: "#333"}, box).textContent = "θ̇" + (i + 1);
    });
  }

  function build(element, S) {
    var root = el("div", {class: "kinlib-ui kinlib-picker", role: "group", "aria-label": "configurations of " + S.title}, null);
    element.appendChild(root);
    F.ensureStyle();
    var X = {S: S, root: root, view: {az: S.view.az || 0.6, el: S.view.el || 0.45}, buttons: []};
    var ctl = el("div", {class: "kinlib-controls", style: "width:auto;flex-basis:100%"}, root);
    var group = el("div", {role: "group", "aria-label": "configuration"}, ctl);
    el("span", {}, group).textContent = "configuration: ";
    S.configs.forEach(function (cf, k) {
      var b = el("button", {type: "button", class: "kinlib-config", "data-name": cf.name, "aria-pressed": "false"}, group);
      b.textContent = cf.name;
      b.addEventListener("click", function () { X.select(k); });
      b.addEventListener("keydown", function (e) { // the arrow keys move between the buttons (and show that configuration)
        var d = {ArrowLeft: -1, ArrowUp: -1, ArrowRight: 1, ArrowDown: 1}[e.key];
        if (!d) return;
        e.preventDefault(); e.stopPropagation();
        var j = (k + d + S.configs.length) % S.configs.length;
        X.buttons[j].focus(); X.select(j);
      });
      b.setAttribute("data-lm-suppress-shortcuts", "true");
      X.buttons.push(b);
    });
    F.picture(X, root, "drawing of " + S.title + " with each joint's velocity arrow at the tool");
    var side = el("div", {class: "kinlib-side", style: "width:300px"}, root);
    X.chart = S.answers === false ? null : svg("svg", {width: 300, height: 220, class: "kinlib-chart", role: "img", "aria-label": "each joint's contribution to the chosen row"}, side);
    X.table = el("div", {class: "kinlib-readout"}, side);
    var ul = el("ul", {class: "kinlib-legend", "aria-label": "legend"}, side);
    F.legendItem(ul, "arm (joints: ○ revolute, □ prismatic)", {stroke: C.arm, "stroke-width": 4});
    for (var i = 0; i < S.n; i++) F.legendItem(ul, "ṗ for θ̇" + (i + 1) + " = 1 (×" + S.scale + ")", {stroke: S.colors[i], "stroke-width": 2.5, "stroke-dasharray": DASH[i % DASH.length] || null});
    X.live = el("div", {class: "kinlib-live kinlib-sr", role: "status", "aria-live": "polite"}, ctl);
    F.orbit(X, side, function () { redraw(); });

    function redraw() {
      F.draw(X, X.st);
      drawArrows(X, X.st);
    }
    X.select = function (k) {
      if (typeof k === "string") k = S.configs.map(function (c) { return c.name; }).indexOf(k);
      var t0 = performance.now(), cf = S.configs[k], n = S.n, st = F.compute(S, cf.q, cf.q.map(function () { return 0; }));
      st.block = null; // the picker draws the arm and its joint-velocity arrows only
      X.k = k; X.st = st;
      var c = []; for (var i = 0; i < n; i++) c.push(st.J[cf.row * n + i]);
      var best = strongest(c), lab = S.rowNames[cf.row];
      X.contributions = c; X.best = best;
      redraw();
      if (S.answers === false) { // the students' version: the arrows only, no bars, table or "largest" (problem 4.1)
        X.buttons.forEach(function (b, j) { b.setAttribute("aria-pressed", String(j === k)); b.classList.toggle("mod-active", j === k); });
        X.table.innerHTML = "<div>θ = (" + cf.q.map(function (x) { return x.toFixed(4); }).join(", ") + ")</div>";
        X.live.textContent = "Configuration " + cf.name + ".";
        root.setAttribute("data-config", cf.name);
        return X;
      }
      bars(X, c, cf.row, cf.name);
      X.buttons.forEach(function (b, j) { b.setAttribute("aria-pressed", String(j === k)); b.classList.toggle("mod-active", j === k); });
      var who = best.length === 1 ? "joint " + best[0] : "a tie between joints " + best.join(" and ");
      X.table.innerHTML = "<div>θ = (" + cf.q.map(function (x) { return x.toFixed(4); }).join(", ") + ")</div><table><tr><th></th>" +
        c.map(function (_, i) { return "<th>θ̇" + (i + 1) + "</th>"; }).join("") + "</tr><tr><th>" + lab + " per unit rate</th>" +
        c.map(function (v, i) { var s = sign(v); return "<td>" + (best.indexOf(i + 1) >= 0 ? "<b>" + s + "</b>" : s) + "</td>"; }).join("") +
        "</tr></table><div class='kinlib-best'>largest |" + lab + "|: " + who + "</div>";
      X.live.textContent = "Configuration " + cf.name + ": " + lab + " per unit joint rate " +
        c.map(function (v, i) { return "θ̇" + (i + 1) + " " + sign(v); }).join(", ") + "; the largest |" + lab + "| is " + who + ".";
      root.setAttribute("data-config", cf.name);
      X.lastMs = performance.now() - t0;
      return X;
    };
    X.select(S.start || 0);
    root.kinlib = X; // for tests and scripts: select(k or name), contributions, best
    return X;
  }

  window.kinlibPicker = function (element, S) { return build(element, F.setScale(S)); };
})();
