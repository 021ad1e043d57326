/* kinlib animation (kinlib/widgets/animation.js): the arm along a path (S.path, N configurations), drawn as the
   explorer draws it (core.js: window.kinlibFront) — arm, ellipses held/free, blocked direction, banner — beside the
   manipulability along the path. Play/pause, one step back/forward and a step slider; an aria-live sentence after
   each step (while playing: when the state changes). Called as kinlibAnimation(element, spec). */
(function () {
  "use strict";
  var F = window.kinlibFront, el = F.el, svg = F.svg, C = F.C, ROWNAMES = F.ROWNAMES, fmt = F.fmt, lengths = F.lengths;

  function thetas(q) { return "(" + q.map(function (x) { return x.toFixed(3); }).join(", ") + ")"; }

  function readout(X, k, st) {
    var S = X.S, sing = st.state === "singular", L = [];
    L.push("step <span class='kinlib-step-no'>" + (k + 1) + "</span> of " + X.N + ": θ = " + thetas(st.q));
    if (S.answers === false) { // the students' version: the arm and its ellipse, no state or manipulability
      L.push("velocity ellipse semi-axes: <span class='kinlib-held'>" + lengths((st.held || st.free).s) + "</span>");
      X.readout.innerHTML = L.join("<br>");
      F.banner(X.status, S, st);
      return;
    }
    L.push(S.wLabel + " = <span class='kinlib-w'>" + (sing ? "0" : st.w.toFixed(4)) + "</span> (" + (sing ? "0" : (100 * st.w / S.wMax).toFixed(1)) +
      "% of its largest value " + S.wMax.toFixed(4) + "; near below " + (100 * S.near.ratio) + "%)");
    if (st.det !== null) L.push("det J = <span class='kinlib-det'>" + (sing ? "0" : (st.det >= 0 ? "+" : "") + fmt(st.det, 4)) + "</span>");
    var s = sing ? st.s.slice(0, -1).concat([0]) : st.s;
    L.push("σ_max = " + fmt(s[0] || 0, 4) + ", σ_min = " + fmt(s[s.length - 1] || 0, 4) + ", rank " + st.rank + " of " + st.full);
    if (st.held) {
      L.push("ṗ ellipse, " + S.hold.map(function (r) { return ROWNAMES[r]; }).join(", ") + " held: semi-axes <span class='kinlib-held'>" + lengths(st.held.s) + "</span>");
      L.push("ṗ ellipse, all joints free: " + lengths(st.free.s));
    } else L.push("velocity ellipse semi-axes: <span class='kinlib-held'>" + lengths(st.free.s) + "</span>");
    X.readout.innerHTML = L.join("<br>");
    F.banner(X.status, S, st);
  }

  // the manipulability along the path: a polyline, the near threshold, a marker per near/singular step, the cursor
  function chart(X, side) {
    var S = X.S, W = 210, H = 150, l = 34, r = 6, t = 18, b = 26, N = X.N;
    var top = Math.max.apply(null, X.ws.concat([S.near.ratio * S.wMax])) * 1.1 || 1;
    var sx = function (k) { return l + (W - l - r) * (N > 1 ? k / (N - 1) : 0); }, sy = function (w) { return H - b - (H - t - b) * w / top; };
    var c = svg("svg", {width: W, height: H, class: "kinlib-chart", role: "img", "aria-label": "manipulability " + S.wLabel + " along the path; the marker is at the step shown"}, side);
    svg("text", {x: W / 2, y: 12, "font-size": 11, "text-anchor": "middle", fill: "#333"}, c).textContent = "manipulability (" + S.rowsLabel + ")";
    svg("path", {d: F.pathOf([[l, t], [l, H - b], [W - r, H - b]]), stroke: "#555", fill: "none"}, c);
    [0, top / 1.1].forEach(function (w) { svg("text", {x: l - 3, y: sy(w) + 4, "font-size": 10, "text-anchor": "end", fill: "#555"}, c).textContent = fmt(w, 2); });
    svg("text", {x: (l + W - r) / 2, y: H - 6, "font-size": 10, "text-anchor": "middle", fill: "#555"}, c).textContent = "step 1 … " + N;
    var yn = sy(S.near.ratio * S.wMax);
    svg("path", {d: F.pathOf([[l, yn], [W - r, yn]]), stroke: C.block, "stroke-width": 1, "stroke-dasharray": "3 3", class: "kinlib-near-line"}, c);
    svg("path", {d: F.pathOf(X.ws.map(function (w, k) { return [sx(k), sy(w)]; })), stroke: C.vel, "stroke-width": 2, fill: "none", class: "kinlib-w-curve"}, c);
    X.states.forEach(function (s, k) {
      if (s === "singular") svg("path", {d: "M" + (sx(k) - 4) + " " + (sy(0) - 4) + " l8 8 m0 -8 l-8 8", stroke: C.block, "stroke-width": 2}, c);
    });
    X.cursor = svg("circle", {r: 5, fill: "none", stroke: "#111", "stroke-width": 2, class: "kinlib-cursor"}, c);
    X.place = function (k) { X.cursor.setAttribute("cx", sx(k)); X.cursor.setAttribute("cy", sy(X.ws[k])); X.cursor.setAttribute("data-step", k); };
  }

  function build(element, S) {
    var root = el("div", {class: "kinlib-ui kinlib-animation", role: "group", "aria-label": "animation of " + S.title}, null);
    element.appendChild(root);
    F.ensureStyle();
    var X = {S: S, root: root, N: S.path.length, k: 0, timer: null, view: {az: S.view.az || 0.6, el: S.view.el || 0.45}};
    // every step's state and manipulability, once (the same compute as each drawn frame)
    var qd0 = S.path[0].map(function () { return 0; });
    var all = S.path.map(function (q) { return F.compute(S, q, qd0); });
    X.states = all.map(function (st) { return st.state; });
    X.ws = all.map(function (st) { return st.state === "singular" ? 0 : st.w; });
    // left the arm, right the manipulability along the path (and the legend), then the controls
    F.picture(X, root, "drawing of " + S.title);
    var side = el("div", {class: "kinlib-side", style: "width:214px"}, root);
    F.armLegend(S, el("ul", {class: "kinlib-legend", "aria-label": "legend"}, side));
    if (S.answers !== false) chart(X, side); else X.place = function () {};
    F.orbit(X, side, function () { F.draw(X, X.st); });
    // controls: play/pause, a step back/forward, the step slider
    var ctl = el("div", {class: "kinlib-controls"}, root);
    el("div", {}, ctl).innerHTML = "<b>along the path</b> (" + X.N + " steps)";
    var player = el("div", {class: "kinlib-player", role: "group", "aria-label": "play the path"}, ctl);
    var prev = el("button", {type: "button", class: "kinlib-prev", "aria-label": "previous step", title: "previous step"}, player);
    prev.textContent = "◀ step";
    var play = el("button", {type: "button", class: "kinlib-play", "aria-label": "play", title: "play / pause", "aria-pressed": "false"}, player);
    play.textContent = "▶ play";
    var next = el("button", {type: "button", class: "kinlib-next", "aria-label": "next step", title: "next step"}, player);
    next.textContent = "step ▶";
    var id = S.id + "-step", lab = el("label", {for: id}, player);
    lab.appendChild(document.createTextNode("step "));
    X.value = el("span", {class: "kinlib-value"}, lab);
    var track = el("div", {class: "kinlib-track"}, player);
    X.input = F.ownKeys(el("input", {type: "range", id: id, min: 0, max: X.N - 1, step: 1, value: 0, class: "kinlib-step", "aria-label": "step along the path"}, track));
    X.readout = el("div", {class: "kinlib-readout"}, ctl);
    X.status = el("div", {class: "kinlib-status"}, ctl);
    X.live = el("div", {class: "kinlib-live kinlib-sr", role: "status", "aria-live": "polite"}, ctl);

    function say(k, st) {
      X.live.textContent = "Step " + (k + 1) + " of " + X.N + ", θ = " + thetas(st.q) + ". " + F.words(S, st);
    }
    X.go = function (k, playing) {
      k = ((k % X.N) + X.N) % X.N; // one step back from the first shows the last: the path loops
      var t0 = performance.now(), before = X.st ? X.st.state : null, st = F.compute(S, S.path[k], qd0);
      X.k = k; X.st = st;
      F.draw(X, st);
      readout(X, k, st);
      X.place(k);
      X.input.value = k;
      X.value.textContent = (k + 1) + " of " + X.N;
      X.input.setAttribute("aria-valuetext", "step " + (k + 1) + " of " + X.N + ", " + st.state);
      if (!playing || st.state !== before) say(k, st);
      root.setAttribute("data-state", st.state);
      root.setAttribute("data-step", k);
      X.lastMs = performance.now() - t0;
      return st;
    };
    X.pause = function () {
      if (X.timer === null) return;
      clearTimeout(X.timer); X.timer = null;
      play.textContent = "▶ play"; play.setAttribute("aria-label", "play"); play.setAttribute("aria-pressed", "false");
      say(X.k, X.st);
    };
    // playing: S.interval ms per step, S.dwell ms on a singular step (time to look at it), and it stops at the last
    // step unless S.loop (a student's pace; no endless motion by default)
    X.play = function () {
      if (X.timer !== null) return;
      play.textContent = "❚❚ pause"; play.setAttribute("aria-label", "pause"); play.setAttribute("aria-pressed", "true");
      if (X.k === X.N - 1) X.go(0, true);
      function wait() { return X.st && X.st.state === "singular" ? Math.max(S.dwell || 0, S.interval) : S.interval; }
      function tick() {
        if (!root.isConnected) { X.pause(); return; } // the output was cleared
        if (X.k === X.N - 1 && !S.loop) { X.pause(); return; }
        X.go(X.k + 1, true);
        X.timer = setTimeout(tick, wait());
      }
      X.timer = setTimeout(tick, wait());
    };
    play.addEventListener("click", function () { if (X.timer === null) X.play(); else X.pause(); });
    prev.addEventListener("click", function () { X.pause(); X.go(X.k - 1); });
    next.addEventListener("click", function () { X.pause(); X.go(X.k + 1); });
    X.input.addEventListener("input", function () { X.pause(); X.go(+X.input.value); });
    X.go(0);
    root.kinlib = X; // for tests and scripts: the state, go(k) to show step k, play(), pause()
    return X;
  }

  window.kinlibAnimation = function (element, S) { return build(element, F.setScale(S)); };
})();
