/* kinlib explorer (kinlib/widgets/explorer.js): a slider per joint, the arm, ṗ = J θ̇, the velocity ellipses, det J,
   manipulability, σ_min/σ_max and the singular set on the sliders; every slider move is computed and drawn here, in the
   browser, by the shared front end (core.js: window.kinlibFront). Called as kinlibExplorer(element, spec). */
(function () {
  "use strict";
  var F = window.kinlibFront, el = F.el, C = F.C, ROWNAMES = F.ROWNAMES, fmt = F.fmt, lengths = F.lengths;
  var compute = F.compute, marksFor = F.marksFor, draw = F.draw, words = F.words, unit = F.unit, valueText = F.valueText;

  function readout(X, st) {
    var S = X.S, sing = st.state === "singular", L = [];
    L.push("task rows of J: (" + S.rows.map(function (r) { return ROWNAMES[r]; }).join(", ") + ")");
    if (S.answers === false) { // the students' version: no det J, manipulability, σ or rank (kinlib.widgets.without_answers)
      if (st.held) L.push("ṗ ellipse, " + S.hold.map(function (r) { return ROWNAMES[r]; }).join(", ") + " held: semi-axes <span class='kinlib-held'>" + lengths(st.held.s) + "</span>");
      else L.push("velocity ellipse semi-axes: <span class='kinlib-held'>" + lengths(st.free.s) + "</span>");
      if (S.showVelocity) L.push("ṗ = (" + st.v.map(function (x) { return (x >= 0 ? "+" : "") + x.toFixed(3); }).join(", ") + ")");
      X.readout.innerHTML = L.join("<br>");
      F.banner(X.status, S, st);
      X.live.textContent = words(S, st);
      return;
    }
    if (st.det !== null) L.push("det J = <span class='kinlib-det'>" + (sing ? "0" : (st.det >= 0 ? "+" : "") + fmt(st.det, 4)) + "</span>");
    L.push("manipulability " + (S.n < S.rows.length ? "√det(JᵀJ)" : "√det(JJᵀ)") + " = <span class='kinlib-w'>" + (sing ? "0" : st.w.toFixed(4)) + "</span>" +
      (S.showMaximum ? " (" + (sing ? "0" : (100 * st.w / S.wMax).toFixed(1)) + "% of its maximum " + S.wMax.toFixed(4) + ")" : ""));
    var s = sing ? st.s.slice(0, -1).concat([0]) : st.s;
    L.push("σ_max = <span class='kinlib-smax'>" + fmt(s[0] || 0, 4) + "</span>, σ_min = <span class='kinlib-smin'>" + fmt(s[s.length - 1] || 0, 4) +
      "</span>, rank " + st.rank + " of " + st.full);
    if (st.held) {
      L.push("ṗ ellipse, " + S.hold.map(function (r) { return ROWNAMES[r]; }).join(", ") + " held: semi-axes <span class='kinlib-held'>" + lengths(st.held.s) + "</span>");
      L.push("ṗ ellipse, all joints free: " + lengths(st.free.s));
    } else L.push("velocity ellipse semi-axes: <span class='kinlib-held'>" + lengths(st.free.s) + "</span>");
    if (S.showVelocity) L.push("ṗ = (" + st.v.map(function (x) { return (x >= 0 ? "+" : "") + x.toFixed(3); }).join(", ") + ")");
    X.readout.innerHTML = L.join("<br>");
    F.banner(X.status, S, st);
    X.live.textContent = words(S, st);
  }

  function update(X) {
    var S = X.S, t0 = performance.now();
    var st = compute(S, X.q, X.qd);
    X.st = st;
    draw(X, st);
    readout(X, st);
    X.sliders.forEach(function (sl, j) { // the singular set on each track, the other joints as they are
      var ms = marksFor(S, X.q, j), box = sl.marks, lo = S.ranges[j][0], hi = S.ranges[j][1];
      while (box.firstChild) box.removeChild(box.firstChild);
      ms.forEach(function (x) {
        var m = el("span", {class: "kinlib-mark", "data-value": x, title: "singular at " + valueText(S, j, x)}, box);
        m.style.left = "calc(7px + (100% - 14px) * " + ((x - lo) / (hi - lo)) + ")";
      });
      sl.desc.textContent = ms.length ? "singular (the other joints as they are) at " + ms.map(function (x) { return valueText(S, j, x); }).join("; ") : "";
    });
    X.root.setAttribute("data-state", st.state);
    X.lastMs = performance.now() - t0;
    X.frames = (X.frames || 0) + 1;
  }

  function build(element, S) {
    var root = el("div", {class: "kinlib-ui kinlib-explorer", role: "group", "aria-label": "explorer of " + S.title}, null);
    element.appendChild(root);
    F.ensureStyle();
    var X = {S: S, root: root, q: S.q0.slice(), qd: S.qd0.slice(), view: {az: S.view.az || 0.6, el: S.view.el || 0.45}};
    // controls
    var ctl = el("div", {class: "kinlib-controls"}, root), sliders = [];
    el("div", {}, ctl).innerHTML = "<b>joint positions</b>";
    function slider(j, rate) {
      var lo = rate ? -2 : S.ranges[j][0], hi = rate ? 2 : S.ranges[j][1], K = rate ? 80 : S.ticks[j];
      var id = S.id + (rate ? "-r" : "-q") + j, lab = el("label", {for: id}, ctl);
      var name = rate ? "θ̇" + (j + 1) + " (" + (S.types[j] === "R" ? "rad/s" : "len/s") + ")" : S.labels[j] + " (" + unit(S, j) + ")";
      lab.appendChild(document.createTextNode(name + " "));
      var out = el("span", {class: "kinlib-value"}, lab);
      var track = el("div", {class: "kinlib-track"}, ctl);
      var x0 = rate ? X.qd[j] : X.q[j];
      var inp = el("input", {type: "range", id: id, min: 0, max: K, step: 1, value: Math.round((x0 - lo) / (hi - lo) * K),
        "aria-label": rate ? "joint rate " + (j + 1) : "joint " + (j + 1) + " position", "data-joint": j + 1, class: rate ? "kinlib-rate" : "kinlib-slider"}, track);
      var marks = el("div", {"aria-hidden": "true"}, track), desc = el("span", {class: "kinlib-sr", id: id + "-d"}, ctl);
      if (!rate) inp.setAttribute("aria-describedby", id + "-d");
      function show(x) {
        out.textContent = x.toFixed(3);
        inp.setAttribute("aria-valuetext", rate ? name + " " + x.toFixed(2) : valueText(S, j, x));
      }
      show(x0);
      inp.addEventListener("input", function () {
        var x = lo + (hi - lo) * (+inp.value) / K;
        if (rate) X.qd[j] = x; else X.q[j] = x;
        show(x); update(X);
      });
      F.ownKeys(inp); // the notebook's own shortcuts (arrow keys move between cells) must not take the slider's keys
      var rec = {input: inp, marks: marks, desc: desc, value: out};
      if (!rate) sliders.push(rec);
      return rec;
    }
    for (var j = 0; j < S.n; j++) slider(j, false);
    X.rateSliders = [];
    if (S.rateSliders) {
      el("div", {style: "margin-top:8px"}, ctl).innerHTML = "<b>joint rates</b> (for the ṗ arrow)";
      for (j = 0; j < S.n; j++) X.rateSliders.push(slider(j, true));
    }
    X.sliders = sliders;
    X.readout = el("div", {class: "kinlib-readout"}, ctl);
    X.status = el("div", {class: "kinlib-status"}, ctl);
    X.live = el("div", {class: "kinlib-live kinlib-sr", role: "status", "aria-live": "polite"}, ctl);
    // the picture: equal axes, drawn at the size it is shown
    F.picture(X, root, "drawing of " + S.title);
    // beside the drawing: the legend and (3-D) the view buttons
    var side = el("div", {class: "kinlib-side", style: "width:210px"}, root);
    var ul = el("ul", {class: "kinlib-legend", "aria-label": "legend"}, side);
    F.armLegend(S, ul);
    if (S.answers !== false) el("li", {class: "kinlib-mark-legend"}, ul).innerHTML = "<span style='color:" + C.mark + "'>▲</span> on a slider: singular there";
    F.orbit(X, side, function () { draw(X, X.st); });
    update(X);
    root.kinlib = X; // for tests and scripts: the state, and set(q) to move the arm
    X.set = function (q) { X.q = q.slice(); sliders.forEach(function (sl, j) { sl.input.value = Math.round((q[j] - S.ranges[j][0]) / (S.ranges[j][1] - S.ranges[j][0]) * S.ticks[j]); }); update(X); return X.st; };
    X.compute = function (q, qd) { return compute(S, q, qd || X.qd); };
    return X;
  }

  window.kinlibExplorer = function (element, S) { return build(element, F.setScale(S)); };
  window.kinlibExplorerMath = {svd: F.svd, eigSym: F.eigSym, det: F.det, compute: compute, marksFor: marksFor}; // for tests
})();
