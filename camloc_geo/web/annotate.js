/* camloc annotation page: plain JavaScript, no dependencies (Leaflet only for the optional map).
 *
 * Pixel convention (as camloc_geo.camera): continuous image coordinates, origin at the
 * top-left corner of the image, x right, y down; the centre of the top-left pixel is
 * (0.5, 0.5). The photo is drawn with its corner at the view offset, so screen and image
 * coordinates differ by one scale and one offset, nothing else.
 *
 * The geometry (vanishing points, principal point, focal length) mirrors
 * camloc_geo/vanishing.py function by function; tests compare the two.
 */
"use strict";
(function () {
  var FORMAT = "camloc-scene/1";
  var AXES = ["length", "width", "height"];
  var COLOURS = { length: "#ff3b30", width: "#c04dff", height: "#ffd60a" };
  var AXIS_WORD = { length: "length", width: "width", height: "height" };
  var CORNER_COLOUR = "#00e5ff";
  var REF_COLOUR = "#34c759";
  var LANDMARK_COLOUR = "#ff9500";
  var PRESETS = {
    sedan: [4.6, 1.8, 1.45], hatchback: [4.2, 1.78, 1.47], suv: [4.7, 1.88, 1.7],
    pickup: [5.6, 2.03, 1.9], van: [5.3, 2.0, 2.3], minivan: [5.1, 1.98, 1.75],
    taxi_ny: [5.0, 1.95, 1.85], bus: [12.0, 2.55, 3.1]
  };
  var INFINITY_DIAGONALS = 1e3;
  var AXIS_POINTS = ["origin", "length", "width", "height"];

  // ------------------------------------------------------------------ geometry (vanishing.py)
  function cross(a, b) {
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  }
  function norm3(v) { return Math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

  /* Eigen-decomposition of a symmetric 3x3 matrix (cyclic Jacobi). Returns
   * {values, vectors} with vectors[k] the unit eigenvector of values[k]. */
  function eigSym3(M) {
    var a = [M[0].slice(), M[1].slice(), M[2].slice()];
    var V = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
    for (var sweep = 0; sweep < 50; sweep++) {
      var off = Math.abs(a[0][1]) + Math.abs(a[0][2]) + Math.abs(a[1][2]);
      if (off < 1e-300) break;
      for (var p = 0; p < 2; p++) {
        for (var q = p + 1; q < 3; q++) {
          if (Math.abs(a[p][q]) < 1e-300) continue;
          var theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
          var t = (theta >= 0 ? 1 : -1) / (Math.abs(theta) + Math.sqrt(theta * theta + 1));
          var c = 1 / Math.sqrt(t * t + 1), s = t * c;
          for (var k = 0; k < 3; k++) {
            var akp = a[k][p], akq = a[k][q];
            a[k][p] = c * akp - s * akq; a[k][q] = s * akp + c * akq;
          }
          for (k = 0; k < 3; k++) {
            var apk = a[p][k], aqk = a[q][k];
            a[p][k] = c * apk - s * aqk; a[q][k] = s * apk + c * aqk;
          }
          for (k = 0; k < 3; k++) {
            var vkp = V[k][p], vkq = V[k][q];
            V[k][p] = c * vkp - s * vkq; V[k][q] = s * vkp + c * vkq;
          }
        }
      }
    }
    return {
      values: [a[0][0], a[1][1], a[2][2]],
      vectors: [0, 1, 2].map(function (j) { return [V[0][j], V[1][j], V[2][j]]; })
    };
  }

  /* Signed misfit of segments to a homogeneous vanishing point (segment_residuals_px). */
  function segmentResiduals(segs, vp) {
    return segs.map(function (s) {
      var mx = (s[0] + s[2]) / 2, my = (s[1] + s[3]) / 2;
      var la = my * vp[2] - vp[1], lb = vp[0] - mx * vp[2], lc = mx * vp[1] - my * vp[0];
      var n = Math.sqrt(la * la + lb * lb);
      if (n < 1e-300) n = 1e-300;
      return (la * s[0] + lb * s[1] + lc) / n;
    });
  }

  function isFinitePoint(vp, scalePx) {
    return Math.abs(vp[2]) * INFINITY_DIAGONALS * scalePx > Math.hypot(vp[0], vp[1]);
  }

  /* Least-squares vanishing point of >= 2 segments (fit_vanishing_point). Returns
   * {homogeneous, pixel, finite, residuals, rms} or {error}. */
  function fitVanishingPoint(segs, scalePx) {
    var n = segs.length;
    if (n < 2) return { error: "needs at least 2 lines, has " + n };
    var lengths = segs.map(function (s) { return Math.hypot(s[2] - s[0], s[3] - s[1]); });
    for (var i = 0; i < n; i++) {
      if (!(lengths[i] >= 1e-6)) return { error: "line " + (i + 1) + " has zero length" };
    }
    var cx = 0, cy = 0;
    segs.forEach(function (s) { cx += s[0] + s[2]; cy += s[1] + s[3]; });
    cx /= 2 * n; cy /= 2 * n;
    var spread = 0;
    segs.forEach(function (s) {
      spread = Math.max(spread, Math.abs(s[0] - cx), Math.abs(s[1] - cy),
        Math.abs(s[2] - cx), Math.abs(s[3] - cy));
    });
    spread = spread || 1;
    var scale = scalePx || spread;
    var meanLen = lengths.reduce(function (a, b) { return a + b; }, 0) / n;
    var weights = lengths.map(function (l) { return Math.sqrt(l / meanLen); });
    var M = [[0, 0, 0], [0, 0, 0], [0, 0, 0]];
    segs.forEach(function (s, k) {
      var l = cross([(s[0] - cx) / scale, (s[1] - cy) / scale, 1],
        [(s[2] - cx) / scale, (s[3] - cy) / scale, 1]);
      var ln = Math.hypot(l[0], l[1]);
      var w = weights[k] / ln;
      l = [l[0] * w, l[1] * w, l[2] * w];
      for (var r = 0; r < 3; r++) for (var c = 0; c < 3; c++) M[r][c] += l[r] * l[c];
    });
    var eig = eigSym3(M);
    var order = [0, 1, 2].sort(function (a, b) { return eig.values[b] - eig.values[a]; });
    var sv = order.map(function (k) { return Math.sqrt(Math.max(eig.values[k], 0)); });
    if (sv[1] < 1e-9 * Math.max(sv[0], 1e-300)) {
      return { error: "all lines lie on one line, so they do not define a vanishing point" };
    }
    var v0 = eig.vectors[order[2]].slice();
    if (v0[2] < 0) v0 = [-v0[0], -v0[1], -v0[2]];
    var segC = segs.map(function (s) {
      return [(s[0] - cx) / scale, (s[1] - cy) / scale, (s[2] - cx) / scale, (s[3] - cy) / scale];
    });
    function unit(x) {
      return [Math.sin(x[0]) * Math.cos(x[1]), Math.sin(x[0]) * Math.sin(x[1]), Math.cos(x[0])];
    }
    function fun(x) {
      return segmentResiduals(segC, unit(x)).map(function (r, k) { return r * weights[k]; });
    }
    function dot(a, b) { var s = 0; for (var k = 0; k < a.length; k++) s += a[k] * b[k]; return s; }
    var vc = v0;
    if (n > 2) {
      var x = [Math.acos(Math.min(1, Math.max(-1, v0[2]))), Math.atan2(v0[1], v0[0])];
      var res = fun(x), cost = dot(res, res), lam = 1e-6;
      for (var it = 0; it < 10; it++) {
        var J0 = [], J1 = [];
        var f0 = fun([x[0] + 1e-7, x[1]]), f1 = fun([x[0], x[1] + 1e-7]);
        for (i = 0; i < res.length; i++) {
          J0.push((f0[i] - res[i]) / 1e-7); J1.push((f1[i] - res[i]) / 1e-7);
        }
        var a00 = dot(J0, J0), a01 = dot(J0, J1), a11 = dot(J1, J1);
        var g0 = dot(J0, res), g1 = dot(J1, res);
        var m00 = a00 + lam * (a00 + 1e-12), m11 = a11 + lam * (a11 + 1e-12);
        var det = m00 * m11 - a01 * a01;
        if (!(Math.abs(det) > 0) || !isFinite(det)) break;
        var dx = [-(m11 * g0 - a01 * g1) / det, -(m00 * g1 - a01 * g0) / det];
        var xn = [x[0] + dx[0], x[1] + dx[1]];
        var rn = fun(xn), costN = dot(rn, rn);
        if (costN < cost) {
          x = xn; res = rn;
          var done = cost - costN <= 1e-10 * cost || Math.max(Math.abs(dx[0]), Math.abs(dx[1])) < 1e-12;
          cost = costN; lam *= 0.3;
          if (done) break;
        } else {
          lam *= 10;
          if (lam > 1e6) break;
        }
      }
      vc = unit(x);
    }
    var vp = [vc[0] * scale + cx * vc[2], vc[1] * scale + cy * vc[2], vc[2]];
    var nv = norm3(vp);
    vp = [vp[0] / nv, vp[1] / nv, vp[2] / nv];
    var residuals = segmentResiduals(segs, vp);
    var diag = scalePx || 2 * spread;
    var finite = isFinitePoint(vp, diag);
    var rms = Math.sqrt(residuals.reduce(function (a, r) { return a + r * r; }, 0) / n);
    return {
      homogeneous: vp, finite: finite, residuals: residuals, rms: rms,
      pixel: finite ? [vp[0] / vp[2], vp[1] / vp[2]] : null
    };
  }

  /* Orthocentre of three finite vanishing points (principal_point_from_orthocentre). */
  function orthocentre(a, b, c) {
    var A = [[b[0] - c[0], b[1] - c[1]], [a[0] - c[0], a[1] - c[1]]];
    var r = [a[0] * (b[0] - c[0]) + a[1] * (b[1] - c[1]), b[0] * (a[0] - c[0]) + b[1] * (a[1] - c[1])];
    var det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    var fro2 = A[0][0] * A[0][0] + A[0][1] * A[0][1] + A[1][0] * A[1][0] + A[1][1] * A[1][1];
    if (Math.abs(det) < 1e-12 * Math.max(fro2, 1e-300)) return null;
    return [(r[0] * A[1][1] - A[0][1] * r[1]) / det, (A[0][0] * r[1] - A[1][0] * r[0]) / det];
  }

  /* Focal length from two orthogonal vanishing points (focal_from_vanishing_pair);
   * returns {focal} or {error}. */
  function focalFromPair(v1, v2, pp) {
    var a = v1.map(function (x) { return x / norm3(v1); });
    var b = v2.map(function (x) { return x / norm3(v2); });
    var cx = pp[0], cy = pp[1];
    var ww = a[2] * b[2];
    var ax = a[0] - cx * a[2], ay = a[1] - cy * a[2], bx = b[0] - cx * b[2], by = b[1] - cy * b[2];
    var dot = ax * bx + ay * by;
    var scale = Math.sqrt((ax * ax + ay * ay) * (bx * bx + by * by));
    if (Math.abs(ww) < 1e-12 * Math.max(scale, 1e-300)) return { error: "at_infinity" };
    var f2 = -dot / ww;
    if (!(f2 > 0)) return { error: "same_side" };
    return { focal: Math.sqrt(f2) };
  }

  /* Intrinsics from up to three vanishing points (estimate_intrinsics without given values
   * unless camera hints are passed). Returns {focal, principalPoint, method, reason} or
   * {error}. */
  function estimateIntrinsics(vps, width, height, hints) {
    hints = hints || {};
    var centre = [width / 2, height / 2];
    var diag = Math.hypot(width, height);
    var pp = hints.principal_point || null;
    if (hints.focal_px && pp) {
      return { focal: hints.focal_px, principalPoint: pp, method: "given", reason: "scene gives both" };
    }
    var finite = {};
    Object.keys(vps).forEach(function (k) {
      var v = vps[k];
      if (!v) return;
      var n = norm3(v);
      if (isFinitePoint([v[0] / n, v[1] / n, v[2] / n], diag)) finite[k] = v;
    });
    var why = "";
    if (!hints.focal_px && !pp && Object.keys(finite).length === 3) {
      var px = AXES.map(function (k) { return [finite[k][0] / finite[k][2], finite[k][1] / finite[k][2]]; });
      var o = orthocentre(px[0], px[1], px[2]);
      if (o === null) {
        why = "orthocentre rejected (the three vanishing points are collinear); ";
      } else {
        var f = focalFromPair(finite.length, finite.width, o);
        if (f.error) {
          why = "orthocentre rejected (" + (f.error === "same_side" ?
            "the vanishing points are not consistent with orthogonal directions" :
            "a vanishing point is at infinity") + "); ";
        } else if (Math.hypot(o[0] - centre[0], o[1] - centre[1]) <= 0.25 * diag) {
          return { focal: f.focal, principalPoint: o, method: "orthocentre",
            reason: "three finite vanishing points; principal point = their orthocentre" };
        } else {
          why = "orthocentre [" + o[0].toFixed(1) + ", " + o[1].toFixed(1) +
            "] is more than 0.25 diagonals from the image centre; ";
        }
      }
    }
    var ppUsed = pp || centre;
    var ppWord = pp ? "given principal point" : "principal point at the image centre";
    if (hints.focal_px) {
      return { focal: hints.focal_px, principalPoint: ppUsed, method: "given_focal",
        reason: why + "focal length given; " + ppWord };
    }
    var names = Object.keys(finite).sort();
    var best = null;
    for (var i = 0; i < names.length; i++) {
      for (var j = i + 1; j < names.length; j++) {
        var a = finite[names[i]], b = finite[names[j]];
        var fr = focalFromPair(a, b, ppUsed);
        if (fr.error) continue;
        var da = Math.hypot(a[0] / a[2] - ppUsed[0], a[1] / a[2] - ppUsed[1]);
        var db = Math.hypot(b[0] / b[2] - ppUsed[0], b[1] / b[2] - ppUsed[1]);
        var quality = -Math.max(da, db) / diag;
        if (best === null || quality > best[0]) best = [quality, fr.focal, names[i] + "+" + names[j]];
      }
    }
    if (best !== null) {
      return { focal: best[1], principalPoint: ppUsed, method: "two_vp",
        reason: why + "focal length from the " + best[2] + " vanishing points; " + ppWord };
    }
    var atInf = Object.keys(vps).filter(function (k) { return vps[k] && !finite[k]; }).sort();
    if (atInf.length) why += "the " + atInf.join(" and ") + " lines are parallel in the image; ";
    return { error: why + "cannot estimate the focal length: fewer than two finite, mutually " +
      "consistent vanishing points" };
  }

  // ------------------------------------------------------------------ the car's own lines
  /* relative.py's CAR_LINE_MARGIN_REL and CAR_LINE_MARGIN_MIN_PX: a line end this far
   * outside the car's outline (of the outline's bounding-box diagonal, at least 2 px) is
   * still on the car. tests/test_browser_annotate.py checks they are the same. */
  var CAR_LINE_MARGIN_REL = 0.05;
  var CAR_LINE_MARGIN_MIN_PX = 2.0;
  var CAR_LINE_AXES = ["length", "width"];
  /* What to draw instead (relative.CAR_LINE_HINTS, "across it" spelled out). */
  var CAR_LINE_HINTS = {
    length: "a kerb, lane line or building edge along the car",
    width: "a stop line, crossing or building edge across the street (along the car's width)"
  };

  /* Convex hull (Andrew's monotone chain) of 2-D points, as relative._convex_hull. */
  function convexHull(points) {
    var seen = {}, pts = [];
    points.forEach(function (p) {
      var key = p[0] + "," + p[1];
      if (!seen[key]) { seen[key] = true; pts.push([p[0], p[1]]); }
    });
    pts.sort(function (a, b) { return a[0] - b[0] || a[1] - b[1]; });
    if (pts.length < 3) return pts;
    function half(seq) {
      var out = [];
      seq.forEach(function (p) {
        while (out.length >= 2) {
          var a = out[out.length - 2], b = out[out.length - 1];
          if ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) > 0) break;
          out.pop();
        }
        out.push(p);
      });
      return out;
    }
    var lower = half(pts), upper = half(pts.slice().reverse());
    return lower.slice(0, -1).concat(upper.slice(0, -1));
  }

  /* Whether both ends of segment s lie inside the hull or within margin px of it
   * (relative._inside_hull). */
  function insideHull(s, hull, margin) {
    if (hull.length < 3) return false;
    var ends = [[s[0], s[1]], [s[2], s[3]]];
    for (var e = 0; e < 2; e++) {
      var worst = -Infinity;
      for (var i = 0; i < hull.length; i++) {
        var a = hull[i], b = hull[(i + 1) % hull.length];
        var nx = b[1] - a[1], ny = -(b[0] - a[0]);
        var n = Math.hypot(nx, ny);
        if (n < 1e-12) n = 1e-12;
        worst = Math.max(worst, (nx * (ends[e][0] - a[0]) + ny * (ends[e][1] - a[1])) / n);
      }
      if (worst > margin) return false;
    }
    return true;
  }

  /* The car's image outline from its four clicks: the hull of the box the three edges from
   * the ground corner span (o + any sum of the edges; relative.py's outline where the
   * fitted camera is not at hand), and the margin a line end may lie outside it.
   * Returns {hull, margin} or null (the car not marked, or its clicks on one line). */
  function carOutline(axes) {
    if (!AXIS_POINTS.every(function (k) { return axes[k]; })) return null;
    var o = axes.origin;
    var e = ["length", "width", "height"].map(function (k) { return [axes[k][0] - o[0], axes[k][1] - o[1]]; });
    var pts = [];
    for (var i = 0; i < 2; i++) for (var j = 0; j < 2; j++) for (var k = 0; k < 2; k++) {
      pts.push([o[0] + i * e[0][0] + j * e[1][0] + k * e[2][0], o[1] + i * e[0][1] + j * e[1][1] + k * e[2][1]]);
    }
    var hull = convexHull(pts);
    if (hull.length < 3) return null;
    var x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
    hull.forEach(function (p) {
      x0 = Math.min(x0, p[0]); x1 = Math.max(x1, p[0]); y0 = Math.min(y0, p[1]); y1 = Math.max(y1, p[1]);
    });
    return { hull: hull, margin: Math.max(CAR_LINE_MARGIN_MIN_PX, CAR_LINE_MARGIN_REL * Math.hypot(x1 - x0, y1 - y0)) };
  }

  /* Per axis of CAR_LINE_AXES with lines: which lines lie on the car (both ends
   * on its outline), the car's own edge of that axis (px), the longest line off the car
   * (px), and warn: no line off the car is at least as long as the car's edge, so the
   * axis rests on the car's own edges (calibrate's car-line warning, issue 24). Empty
   * before the car is marked. */
  function carLines(st) {
    var out = {};
    var outline = carOutline(st.axes);
    if (!outline) return out;
    CAR_LINE_AXES.forEach(function (k) {
      var segs = st.lines[k];
      if (!segs.length) return;
      var o = st.axes.origin, edge = Math.hypot(st.axes[k][0] - o[0], st.axes[k][1] - o[1]);
      var onCar = segs.map(function (s) { return insideHull(s, outline.hull, outline.margin); });
      var longestOff = 0;
      segs.forEach(function (s, i) {
        if (!onCar[i]) longestOff = Math.max(longestOff, Math.hypot(s[2] - s[0], s[3] - s[1]));
      });
      var nCar = onCar.filter(Boolean).length;
      out[k] = { onCar: onCar, nCar: nCar, n: segs.length, edgePx: edge, longestOffPx: longestOff,
        warn: nCar > 0 && longestOff < edge };
    });
    return out;
  }

  /* The car's top (point 4) not above its ground corner (point 1) on screen: the four points
     clicked in another order. The top is straight above the corner, and a street camera does
     not roll by 90 degrees. */
  function topNotAbove(ax) { return !!(ax.origin && ax.height && ax.height[1] >= ax.origin[1] - 1); }

  /* Everything the checks panel shows, from an annotation state (pure: tests call it). */
  function analyse(st, width, height, hints) {
    var diag = Math.hypot(width, height);
    var out = { vps: {}, intrinsics: null, horizon: null, messages: [], wrongCorner: null, topBelow: false,
      carOutline: carOutline(st.axes), carLines: carLines(st) };
    var hv = {};
    AXES.forEach(function (k) {
      var segs = st.lines[k];
      if (segs.length < 2) { out.vps[k] = null; return; }
      var vp = fitVanishingPoint(segs, diag);
      out.vps[k] = vp;
      if (!vp.error) hv[k] = vp.homogeneous;
    });
    if (Object.keys(hv).length >= 2) out.intrinsics = estimateIntrinsics(hv, width, height, hints);
    if (hv.length && hv.width) {
      var h = cross(hv.length, hv.width);
      if (Math.hypot(h[0], h[1]) > 1e-12 * Math.abs(h[2])) out.horizon = h;
    }
    // Points in the wrong order: a top clicked at or below the first point (the four clicked
    // in another order: the top first, or the ground corner last) was said nothing of until
    // lines were drawn, and then only as "Wrong corner?" of the length end (session 42 QA, a
    // real photo on a phone).
    out.topBelow = topNotAbove(st.axes);
    // Wrong corner: moving from the origin along an axis away from the camera moves the
    // image toward that axis' vanishing point (a point at infinity ahead of the camera).
    var ax = st.axes;
    if (ax.origin) {
      ["length", "width"].forEach(function (k) {
        if (!ax[k] || !hv[k]) return;
        var v = hv[k], o = ax.origin, s = [ax[k][0] - o[0], ax[k][1] - o[1]];
        if (Math.hypot(s[0], s[1]) < 1) return;
        var toVp = [v[0] - o[0] * v[2], v[1] - o[1] * v[2]];
        var d = (toVp[0] * s[0] + toVp[1] * s[1]) * v[2];
        var den = Math.hypot(toVp[0], toVp[1]) * Math.hypot(s[0], s[1]) * Math.abs(v[2]);
        if (den > 0 && d < -0.2 * den) out.wrongCorner = out.wrongCorner || k;
      });
    }
    return out;
  }

  // expose the pure functions (tests evaluate them against camloc_geo.vanishing)
  window.camlocGeometry = {
    fitVanishingPoint: fitVanishingPoint, estimateIntrinsics: estimateIntrinsics,
    orthocentre: orthocentre, focalFromPair: focalFromPair, analyse: analyse,
    segmentResiduals: segmentResiduals, convexHull: convexHull, insideHull: insideHull,
    carOutline: carOutline, carLines: carLines,
    carLineMargin: { rel: CAR_LINE_MARGIN_REL, minPx: CAR_LINE_MARGIN_MIN_PX }
  };

  // ------------------------------------------------------------------ page set-up
  var config = JSON.parse(document.getElementById("camloc-config").textContent);
  var W = config.image.width, H = config.image.height;
  var DIAG = Math.hypot(W, H);
  var $ = function (id) { return document.getElementById(id); };
  var canvas = $("canvas"), ctx = canvas.getContext("2d");
  var photo = new Image();
  var photoReady = false;

  var STEPS = [
    { key: "car", title: "Mark the car" },
    { key: "length", title: "Lines along the car's length" },
    { key: "width", title: "Lines along the car's width" },
    { key: "height", title: "Upright lines (height)" },
    { key: "corners", title: "Kerb corners of the junction" },
    { key: "extras", title: "Known places (optional)" },
    { key: "save", title: config.mode === "crowd" ? "Check and submit" : "Check and save" }
  ];

  function emptyState() {
    return {
      axes: { origin: null, length: null, width: null, height: null },
      lines: { length: [], width: [], height: [] },
      corners: [], references: [], landmarks: [],
      annotator: "", object: null
    };
  }

  var S = emptyState();
  var base = null;        // the scene being edited (kept whole, so unknown fields survive)
  var annIndex = 0;       // which of base.annotations this page edits
  var step = 0;
  var undoStack = [], redoStack = [];
  var view = { scale: 1, tx: 0, ty: 0 };
  var pending = null;     // first end of a line being drawn: [x, y]
  var mouseImg = null;    // cursor in image coordinates
  var hover = null;       // point under the cursor: {kind, ...}
  var selected = null;    // point last tapped or clicked without moving: what Delete removes
  var drag = null;        // {target, moved} while moving a point, or {pan:true,...}
  var extrasKind = "reference";
  var analysis = analyse(S, W, H, {});
  var lastSaved = null;
  var leafletMap = null;

  function snapshot() { return JSON.stringify(S); }
  function commit() {
    undoStack.push(snapshot());
    if (undoStack.length > 500) undoStack.shift();
    redoStack = [];
  }
  /* The first step whose clicks differ between two states, or -1. Undo and redo go there:
   * undoing the car's points from step 2 left the page on step 2, so the next click drew a
   * length line where the grader meant to click the car again. */
  function stepOfChange(a, b) {
    var parts = [
      [a.axes, b.axes], [a.lines.length, b.lines.length], [a.lines.width, b.lines.width],
      [a.lines.height, b.lines.height], [a.corners, b.corners],
      [[a.references, a.landmarks], [b.references, b.landmarks]]
    ];
    for (var i = 0; i < parts.length; i++) {
      if (JSON.stringify(parts[i][0]) !== JSON.stringify(parts[i][1])) return i;
    }
    return -1;
  }
  function restore(text) {
    var before = S;
    S = JSON.parse(text);
    var k = stepOfChange(before, S);
    if (k >= 0 && k !== step) { step = k; pending = null; }
    changed();
  }
  function undo() {
    if (pending) { pending = null; render(); return; }
    if (!undoStack.length) return;
    redoStack.push(snapshot());
    restore(undoStack.pop());
  }
  function redo() {
    if (!redoStack.length) return;
    undoStack.push(snapshot());
    restore(redoStack.pop());
  }

  // ------------------------------------------------------------------ scene in and out
  function num(v) { return typeof v === "number" && isFinite(v); }
  function pixelOk(p) {
    return Array.isArray(p) && p.length === 2 && num(p[0]) && num(p[1]) &&
      p[0] >= 0 && p[0] <= W && p[1] >= 0 && p[1] <= H;
  }

  /* Checks a loaded scene the way camloc_geo.scene does for what the page edits; returns
   * an error message naming the field, or null. */
  function validateScene(sc) {
    if (!sc || typeof sc !== "object" || Array.isArray(sc)) return "a scene is a JSON object";
    if (sc.format !== FORMAT) return "format: expected \"" + FORMAT + "\", got " + JSON.stringify(sc.format);
    if (!sc.image || !num(sc.image.width) || !num(sc.image.height)) return "image: width and height are required";
    if (sc.image.width !== W || sc.image.height !== H) {
      return "the scene is for a " + sc.image.width + "x" + sc.image.height + " image, but this photo is " +
        W + "x" + H + ": open the scene with the photo it was made on";
    }
    var anns = sc.annotations || [];
    if (!Array.isArray(anns)) return "annotations: must be a list";
    for (var i = 0; i < anns.length; i++) {
      var a = anns[i];
      if (!a || !a.axes) return "annotations[" + i + "].axes: required field is missing";
      for (var k = 0; k < 4; k++) {
        if (!pixelOk(a.axes[AXIS_POINTS[k]])) {
          return "annotations[" + i + "].axes." + AXIS_POINTS[k] + ": must be a pixel [x, y] inside the image";
        }
      }
      var vl = a.vp_lines || {};
      for (k = 0; k < 3; k++) {
        var segs = vl[AXES[k]] || [];
        if (!Array.isArray(segs)) return "annotations[" + i + "].vp_lines." + AXES[k] + ": must be a list";
        for (var j = 0; j < segs.length; j++) {
          var s = segs[j];
          if (!Array.isArray(s) || s.length !== 4 || !pixelOk([s[0], s[1]]) || !pixelOk([s[2], s[3]])) {
            return "annotations[" + i + "].vp_lines." + AXES[k] + "[" + j + "]: must be [x1, y1, x2, y2] inside the image";
          }
        }
      }
    }
    if (sc.intersection) {
      var cs = sc.intersection.corners;
      if (!Array.isArray(cs) || !cs.length) return "intersection.corners: at least one corner";
      for (i = 0; i < cs.length; i++) if (!pixelOk(cs[i])) return "intersection.corners[" + i + "]: must be a pixel inside the image";
    }
    var refs = sc.references || [];
    for (i = 0; i < refs.length; i++) {
      if (!refs[i] || !pixelOk(refs[i].pixel)) return "references[" + i + "].pixel: must be a pixel inside the image";
      if (!num(refs[i].lat) || !num(refs[i].lon)) return "references[" + i + "]: lat and lon are required";
    }
    var lms = sc.landmarks || [];
    for (i = 0; i < lms.length; i++) {
      if (!lms[i] || !pixelOk(lms[i].pixel)) return "landmarks[" + i + "].pixel: must be a pixel inside the image";
    }
    return null;
  }

  function loadScene(sc, index) {
    base = JSON.parse(JSON.stringify(sc));
    annIndex = index || 0;
    S = emptyState();
    var anns = base.annotations || [];
    var a = anns[annIndex];
    if (a) {
      AXIS_POINTS.forEach(function (k) { S.axes[k] = a.axes[k].slice(); });
      AXES.forEach(function (k) {
        S.lines[k] = ((a.vp_lines || {})[k] || []).map(function (s) { return s.slice(); });
      });
      S.annotator = a.annotator || "";
    } else {
      annIndex = anns.length;
    }
    S.corners = base.intersection ? base.intersection.corners.map(function (c) { return c.slice(); }) : [];
    S.references = (base.references || []).map(function (r) { return JSON.parse(JSON.stringify(r)); });
    S.landmarks = (base.landmarks || []).map(function (r) { return JSON.parse(JSON.stringify(r)); });
    undoStack = []; redoStack = [];
    pending = null;
    step = firstIncompleteStep();
    changed();
  }

  function sceneId() {
    var n = config.image.name || "scene";
    return n.replace(/\.[A-Za-z0-9]+$/, "") || "scene";
  }

  function clone(x) { return JSON.parse(JSON.stringify(x)); }

  function carComplete() { return AXIS_POINTS.every(function (k) { return !!S.axes[k]; }); }

  /* The scene file: the loaded scene with this page's fields replaced. */
  function buildScene() {
    var sc = base ? clone(base) : {
      format: FORMAT, id: sceneId(),
      image: { width: W, height: H, path: config.image.name }
    };
    if (!base && config.prior) sc.prior = { lat: config.prior.lat, lon: config.prior.lon, radius_m: 150 };
    if (S.object) sc.object = clone(S.object);
    var anns = sc.annotations ? sc.annotations : [];
    if (carComplete()) {
      var old = anns[annIndex] || {};
      var ann = clone(old);
      ann.annotator = S.annotator || old.annotator || "anonymous";
      if (!old.annotator && !S.annotator) ann.annotator = "anonymous";
      ann.axes = {};
      AXIS_POINTS.forEach(function (k) { ann.axes[k] = S.axes[k].slice(); });
      var vl = old.vp_lines ? clone(old.vp_lines) : {};
      AXES.forEach(function (k) {
        if (S.lines[k].length || (old.vp_lines && k in old.vp_lines) || !old.axes) {
          vl[k] = S.lines[k].map(function (s) { return s.slice(); });
        } else {
          delete vl[k];
        }
      });
      if (Object.keys(vl).length || old.vp_lines) ann.vp_lines = vl;
      if (!old.annotator && S.annotator === "" && old.axes) delete ann.annotator;
      anns[annIndex] = ann;
    } else if (anns[annIndex]) {
      anns.splice(annIndex, 1);
    }
    if (anns.length || sc.annotations) sc.annotations = anns;
    if (S.corners.length) {
      var inter = sc.intersection ? sc.intersection : junctionHint();
      inter.corners = S.corners.map(function (c) { return c.slice(); });
      sc.intersection = inter;
    } else {
      delete sc.intersection;
    }
    var refs = S.references.filter(function (r) { return num(r.lat) && num(r.lon); });
    if (refs.length || sc.references) sc.references = clone(refs);
    var lms = S.landmarks.filter(function (l) { return l.name || (num(l.lat) && num(l.lon)); });
    if (lms.length || sc.landmarks) sc.landmarks = clone(lms);
    return sc;
  }

  /* lat/lon of the junction on the map, when the page was made with one. */
  function junctionHint() {
    var hint = {};
    var inters = mapIntersections();
    if (inters.length === 1) {
      hint.lat = inters[0].geometry.coordinates[1];
      hint.lon = inters[0].geometry.coordinates[0];
    }
    return hint;
  }
  function mapIntersections() {
    if (!config.corners || !config.corners.features) return [];
    return config.corners.features.filter(function (f) { return f.properties && f.properties.kind === "intersection"; });
  }

  /* What is still missing, per step (empty list = done). */
  function missing(key) {
    var m = [];
    if (key === "car") {
      var words = { origin: "the ground under the body's corner nearest the camera", length: "the far end of the length edge",
        width: "the far end of the width edge", height: "the top of the height edge" };
      AXIS_POINTS.forEach(function (k) { if (!S.axes[k]) m.push(words[k]); });
    } else if (AXES.indexOf(key) >= 0) {
      var n = S.lines[key].length;
      if (n < 2) m.push((2 - n) + " more " + AXIS_WORD[key] + " line" + (n === 1 ? "" : "s"));
    } else if (key === "corners") {
      if (!S.corners.length) m.push("the visible kerb corners (or skip if none is visible)");
    } else if (key === "extras") {
      S.references.forEach(function (r, i) {
        if (!(num(r.lat) && num(r.lon))) m.push("lat/lon of place " + (i + 1));
      });
      S.landmarks.forEach(function (l, i) { if (!l.name) m.push("the name of landmark " + (i + 1)); });
    } else if (key === "save") {
      ["car", "length", "width", "height"].forEach(function (k) {
        if (missing(k).length) m.push("step " + (STEPS.findIndex(function (s) { return s.key === k; }) + 1) + ": " + missing(k).join(", "));
      });
    }
    return m;
  }
  function optional(key) { return key === "corners" || key === "extras"; }
  function firstIncompleteStep() {
    for (var i = 0; i < 4; i++) if (missing(STEPS[i].key).length) return i;
    return S.corners.length ? 6 : 4;
  }

  // ------------------------------------------------------------------ view
  function resize() {
    var r = canvas.getBoundingClientRect();
    var dpr = window.devicePixelRatio || 1;
    canvas.width = Math.max(1, Math.round(r.width * dpr));
    canvas.height = Math.max(1, Math.round(r.height * dpr));
    render();
  }
  function fit() {
    var r = canvas.getBoundingClientRect();
    var s = Math.min(r.width / W, r.height / H);
    view.scale = s;
    view.tx = (r.width - W * s) / 2;
    view.ty = (r.height - H * s) / 2;
    render();
  }
  function toScreen(p) { return [p[0] * view.scale + view.tx, p[1] * view.scale + view.ty]; }
  function toImage(sx, sy) { return [(sx - view.tx) / view.scale, (sy - view.ty) / view.scale]; }
  function zoomAt(factor, sx, sy) {
    var s = Math.min(Math.max(view.scale * factor, 0.02), 40);
    var p = toImage(sx, sy);
    view.scale = s;
    view.tx = sx - p[0] * s;
    view.ty = sy - p[1] * s;
    render();
  }
  function eventPos(e) {
    var r = canvas.getBoundingClientRect();
    return [e.clientX - r.left, e.clientY - r.top];
  }

  // ------------------------------------------------------------------ points under the cursor
  function allTargets() {
    var t = [];
    AXIS_POINTS.forEach(function (k) { if (S.axes[k]) t.push({ kind: "axis", key: k, p: S.axes[k], step: 0 }); });
    AXES.forEach(function (k, ai) {
      S.lines[k].forEach(function (s, i) {
        t.push({ kind: "line", axis: k, index: i, end: 0, p: [s[0], s[1]], step: ai + 1 });
        t.push({ kind: "line", axis: k, index: i, end: 1, p: [s[2], s[3]], step: ai + 1 });
      });
    });
    S.corners.forEach(function (c, i) { t.push({ kind: "corner", index: i, p: c, step: 4 }); });
    S.references.forEach(function (r, i) { t.push({ kind: "reference", index: i, p: r.pixel, step: 5 }); });
    S.landmarks.forEach(function (r, i) { t.push({ kind: "landmark", index: i, p: r.pixel, step: 5 }); });
    return t;
  }
  function targetAt(sx, sy) {
    var best = null, bestD = 9;
    var all = STEPS[step].key === "save";
    allTargets().forEach(function (t) {
      // Points of the current step move (all of them in the last step): a line may start
      // on a car corner without grabbing it.
      if (!all && t.step !== step) return;
      var q = toScreen(t.p);
      var d = Math.hypot(q[0] - sx, q[1] - sy);
      if (d < bestD) { bestD = d; best = t; }
    });
    return best;
  }
  function setTarget(t, p) {
    p = [Math.min(Math.max(p[0], 0), W), Math.min(Math.max(p[1], 0), H)];
    if (t.kind === "axis") S.axes[t.key] = p;
    else if (t.kind === "line") {
      var s = S.lines[t.axis][t.index];
      if (t.end === 0) { s[0] = p[0]; s[1] = p[1]; } else { s[2] = p[0]; s[3] = p[1]; }
    } else if (t.kind === "corner") S.corners[t.index] = p;
    else if (t.kind === "reference") S.references[t.index].pixel = p;
    else if (t.kind === "landmark") S.landmarks[t.index].pixel = p;
  }
  function deleteTarget(t) {
    commit();
    if (t.kind === "axis") S.axes[t.key] = null;
    else if (t.kind === "line") S.lines[t.axis].splice(t.index, 1);
    else if (t.kind === "corner") S.corners.splice(t.index, 1);
    else if (t.kind === "reference") S.references.splice(t.index, 1);
    else if (t.kind === "landmark") S.landmarks.splice(t.index, 1);
    hover = null;
    changed();
  }

  // ------------------------------------------------------------------ placing points
  function place(p) {
    if (p[0] < 0 || p[0] > W || p[1] < 0 || p[1] > H) {
      flash("Click inside the photo.");
      return;
    }
    var key = STEPS[step].key;
    if (key === "car") {
      var next = AXIS_POINTS.filter(function (k) { return !S.axes[k]; })[0];
      if (!next) { flash("The four car points are placed: drag one to move it, or go to the next step."); return; }
      commit();
      S.axes[next] = p;
      // moves on by itself, unless the four points are plainly in the wrong order (the top
      // not above the ground corner): then the step stays, its red check over the photo
      if (carComplete() && step === 0 && !topNotAbove(S.axes)) step = 1;
    } else if (AXES.indexOf(key) >= 0) {
      if (!pending) { pending = p; render(); return; }
      var sp = toScreen(pending), sq = toScreen(p);
      if (Math.hypot(sq[0] - sp[0], sq[1] - sp[1]) < 4) { flash("Too short: click the other end of the line."); return; }
      commit();
      S.lines[key].push([pending[0], pending[1], p[0], p[1]]);
      pending = null;
    } else if (key === "corners") {
      commit();
      S.corners.push(p);
    } else if (key === "extras") {
      commit();
      if (extrasKind === "landmark") S.landmarks.push({ pixel: p, kind: "building_corner", name: "" });
      else S.references.push({ pixel: p, lat: null, lon: null });
    } else {
      flash("Nothing to click in this step: save, or go back to a step to change it.");
      return;
    }
    changed();
  }

  // ------------------------------------------------------------------ drawing
  function render() {
    var dpr = window.devicePixelRatio || 1;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    var cw = canvas.width / dpr, ch = canvas.height / dpr;
    ctx.clearRect(0, 0, cw, ch);
    if (photoReady) {
      ctx.imageSmoothingEnabled = view.scale < 2;
      ctx.drawImage(photo, view.tx, view.ty, W * view.scale, H * view.scale);
    }
    ctx.lineCap = "round";
    drawHorizon(cw, ch);
    drawVpGuides();
    AXES.forEach(function (k, ai) {
      S.lines[k].forEach(function (s, i) {
        var a = toScreen([s[0], s[1]]), b = toScreen([s[2], s[3]]);
        var active = step === ai + 1;
        seg(a, b, COLOURS[k], active ? 3 : 2);
        dot(a, COLOURS[k], 3.5); dot(b, COLOURS[k], 3.5);
        label([(a[0] + b[0]) / 2, (a[1] + b[1]) / 2], k[0].toUpperCase() + (i + 1), COLOURS[k]);
      });
    });
    if (pending && mouseImg) {
      seg(toScreen(pending), toScreen(mouseImg), COLOURS[STEPS[step].key] || "#fff", 2, [6, 4]);
    }
    if (pending) dot(toScreen(pending), COLOURS[STEPS[step].key] || "#fff", 4);
    drawCarOutline();
    drawCar();
    S.corners.forEach(function (c, i) { badge(toScreen(c), String(i + 1), CORNER_COLOUR, "#002b33"); });
    S.references.forEach(function (r, i) { badge(toScreen(r.pixel), "P" + (i + 1), REF_COLOUR, "#062b12"); });
    S.landmarks.forEach(function (r, i) { badge(toScreen(r.pixel), "B" + (i + 1), LANDMARK_COLOUR, "#3a1f00"); });
    if (hover) {
      var q = toScreen(hover.p);
      ctx.strokeStyle = "#fff"; ctx.lineWidth = 2; ctx.setLineDash([]);
      ctx.beginPath(); ctx.arc(q[0], q[1], 10, 0, 2 * Math.PI); ctx.stroke();
    }
  }
  function seg(a, b, colour, width, dash) {
    ctx.setLineDash(dash || []);
    ctx.strokeStyle = "rgba(0,0,0,0.6)"; ctx.lineWidth = width + 2;
    ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke();
    ctx.strokeStyle = colour; ctx.lineWidth = width;
    ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke();
    ctx.setLineDash([]);
  }
  function dot(p, colour, r) {
    ctx.fillStyle = colour; ctx.strokeStyle = "#000"; ctx.lineWidth = 1;
    ctx.beginPath(); ctx.arc(p[0], p[1], r, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
  }
  function label(p, text, colour) {
    ctx.font = "bold 12px system-ui, sans-serif";
    var w = ctx.measureText(text).width;
    ctx.fillStyle = "rgba(0,0,0,0.65)";
    ctx.fillRect(p[0] + 5, p[1] - 16, w + 6, 15);
    ctx.fillStyle = colour;
    ctx.fillText(text, p[0] + 8, p[1] - 4);
  }
  function badge(p, text, fill, textColour) {
    ctx.font = "bold 12px system-ui, sans-serif";
    var w = Math.max(18, ctx.measureText(text).width + 8);
    ctx.fillStyle = fill; ctx.strokeStyle = "#000"; ctx.lineWidth = 1.5;
    dot(p, fill, 4);
    ctx.beginPath();
    ctx.rect(p[0] + 6, p[1] - 22, w, 17);
    ctx.fill(); ctx.stroke();
    ctx.fillStyle = textColour;
    ctx.fillText(text, p[0] + 10, p[1] - 9);
  }
  function drawCar() {
    var ax = S.axes;
    if (ax.origin) {
      var o = toScreen(ax.origin);
      ["length", "width", "height"].forEach(function (k) {
        if (!ax[k]) return;
        var e = toScreen(ax[k]);
        seg(o, e, COLOURS[k], 3);
        dot(e, COLOURS[k], 5);
        label(e, { length: "length end", width: "width end", height: "top" }[k], COLOURS[k]);
      });
      dot(o, "#ffffff", 6);
      label(o, analysis.wrongCorner ? "origin (wrong corner?)" : "origin", analysis.wrongCorner ? "#ff6b6b" : "#ffffff");
    }
  }
  /* The car's outline, dashed, while an axis rests on the car's own lines: lines inside
   * it count as the car's. */
  function drawCarOutline() {
    var cl = analysis.carLines, ol = analysis.carOutline;
    if (!ol || !CAR_LINE_AXES.some(function (k) { return cl[k] && cl[k].warn; })) return;
    var pts = ol.hull.map(toScreen);
    ctx.setLineDash([6, 4]);
    ctx.lineWidth = 3; ctx.strokeStyle = "rgba(0,0,0,0.6)";
    ctx.beginPath();
    pts.forEach(function (p, i) { if (i) ctx.lineTo(p[0], p[1]); else ctx.moveTo(p[0], p[1]); });
    ctx.closePath(); ctx.stroke();
    ctx.lineWidth = 1.5; ctx.strokeStyle = "#ffb340";
    ctx.stroke();
    ctx.setLineDash([]);
    var top = pts.reduce(function (a, b) { return b[1] < a[1] ? b : a; });
    label([top[0], top[1] - 14], "the car: lines inside are its own", "#ffb340");
  }
  function drawHorizon(cw, ch) {
    var h = analysis.horizon;
    if (!h) return;
    // a x + b y + c = 0 in image pixels, drawn across the photo's width
    var pts = [];
    if (Math.abs(h[1]) > Math.abs(h[0]) * 1e-6) {
      [0, W].forEach(function (x) { pts.push([x, -(h[0] * x + h[2]) / h[1]]); });
    } else {
      [0, H].forEach(function (y) { pts.push([-(h[1] * y + h[2]) / h[0], y]); });
    }
    var a = toScreen(pts[0]), b = toScreen(pts[1]);
    seg(a, b, "#7fdbff", 2, [12, 6]);
    var at = toScreen([pts[0][0] + (pts[1][0] - pts[0][0]) * 0.04, pts[0][1] + (pts[1][1] - pts[0][1]) * 0.04]);
    label(at, "horizon (the camera's eye level)", "#7fdbff");
  }
  function drawVpGuides() {
    AXES.forEach(function (k, ai) {
      var vp = analysis.vps[k];
      if (!vp || vp.error) return;
      var active = step === ai + 1;
      S.lines[k].forEach(function (s) {
        var m = [(s[0] + s[2]) / 2, (s[1] + s[3]) / 2];
        var tgt;
        if (vp.finite) tgt = vp.pixel;
        else {
          var d = [vp.homogeneous[0], vp.homogeneous[1]];
          var n = Math.hypot(d[0], d[1]);
          var far = DIAG * 3;
          tgt = [m[0] + d[0] / n * far, m[1] + d[1] / n * far];
          var tgt2 = [m[0] - d[0] / n * far, m[1] - d[1] / n * far];
          ctx.globalAlpha = active ? 0.7 : 0.3;
          seg(toScreen(m), toScreen(tgt2), COLOURS[k], 1, [3, 5]);
          ctx.globalAlpha = 1;
        }
        ctx.globalAlpha = active ? 0.7 : 0.3;
        seg(toScreen(m), toScreen(tgt), COLOURS[k], 1, [3, 5]);
        ctx.globalAlpha = 1;
      });
      if (vp.finite) {
        var q = toScreen(vp.pixel);
        ctx.strokeStyle = COLOURS[k]; ctx.lineWidth = 2;
        ctx.beginPath(); ctx.moveTo(q[0] - 8, q[1] - 8); ctx.lineTo(q[0] + 8, q[1] + 8);
        ctx.moveTo(q[0] - 8, q[1] + 8); ctx.lineTo(q[0] + 8, q[1] - 8); ctx.stroke();
        label(q, AXIS_WORD[k] + " lines meet", COLOURS[k]);
      }
    });
  }

  // ------------------------------------------------------------------ the side panel
  /* The drawing of which point is the car's ground corner (web/ground-corner.svg, inlined). */
  function groundCornerDrawing() {
    var t = document.getElementById("ground-corner-drawing");
    return t ? "<figure id='ground-corner' class='drawing'>" + t.innerHTML + "</figure>" : "";
  }
  var STEP_TEXT = {
    car: function () {
      return "<p>Pick <b>the most visible car</b>: one whose length, width and height you can all see, " +
        "ideally parked or stopped near the middle of the photo. Then click four points on it, in this order:</p>" +
        groundCornerDrawing() +
        "<ol><li><b>its ground corner nearest the camera</b>: the point on the road <b>straight under the corner of the body</b> " +
        "(the bumper's corner), on the corner closest to you. A rounded car has no corner on the road: " +
        "imagine the box around the body; <b>not</b> where the tyre touches the road;</li>" +
        "<li>the far end of its <span class='swatch' style='background:" + COLOURS.length + "'></span><b>length</b> edge " +
        "(the ground under the body's corner at the other end of the same side);</li>" +
        "<li>the far end of its <span class='swatch' style='background:" + COLOURS.width + "'></span><b>width</b> edge " +
        "(the ground under the body's corner across the car's front or back);</li>" +
        "<li>the <span class='swatch' style='background:" + COLOURS.height + "'></span><b>top</b> of the car straight above the first corner (at its roof's height).</li></ol>" +
        "<p class='muted small'>Hidden corners: click where they would be. The car is assumed to be a sedan; change it in the last step.</p>";
    },
    length: function () {
      return lineText("length", "parallel to the car's length: kerbs, lane markings, road edges and building edges along the street, " +
        "and the car's own sides", true);
    },
    width: function () {
      return lineText("width", "parallel to the car's width: stop lines, crossings, kerbs of the cross street, building edges, " +
        "and the car's front or back edge", true);
    },
    height: function () { return lineText("height", "that stand straight up: the car's corners, poles, lamp posts, building edges"); },
    corners: function () {
      var txt = "<p>Click the <b>kerb corners of the junction</b> that you can see (where the kerbs of two streets meet), " +
        "<b>clockwise</b> as you see them on the screen. A corner you cannot see is left out.</p>";
      if (mapIntersections().length) txt += "<p>The map below shows the junction's corners numbered clockwise, from above.</p>";
      txt += "<p class='muted small'>No junction in view? Skip this step.</p>";
      return txt;
    },
    extras: function () {
      return "<p>Optional. If you know where a spot on the ground is, click it and type its <b>latitude and longitude</b>; " +
        "or click the ground corner (or face middle) of a <b>named building</b> and type its name.</p>" +
        "<label><input type='radio' name='xk' value='reference'" + (extrasKind === "reference" ? " checked" : "") + "> place with lat/lon</label>" +
        "<label><input type='radio' name='xk' value='landmark'" + (extrasKind === "landmark" ? " checked" : "") + "> named building (landmark)</label>";
    },
    save: function () {
      return "<p>Look at the checks below; a warning usually means one point or line is off. Then " +
        (config.mode === "crowd" ? "<b>submit</b> your work." : "<b>save</b> the scene file (it downloads) and run <code>camloc calibrate</code> on it.") + "</p>";
    }
  };
  function lineText(k, what, carHint) {
    return "<p>Draw <b>two or more lines</b> " + what + ". Click one end, then the other end. " +
      "Long lines far apart help most.</p>" +
      (carHint ? "<p class='car-hint'>Draw at least one line <b>off the car</b>, as long as the car's " + k + " edge or longer: " +
        "a rounded car's own edges are curved and bias the result.</p>" : "") +
      "<p><span class='swatch' style='background:" + COLOURS[k] + "'></span>" +
      "Dotted guides show where the lines meet; they should all cross in one point (far away is fine).</p>";
  }

  function stepState(i) {
    var k = STEPS[i].key, m = missing(k);
    if (k === "car") return (4 - m.length) + "/4 points";
    if (AXES.indexOf(k) >= 0) return S.lines[k].length + " line" + (S.lines[k].length === 1 ? "" : "s");
    if (k === "corners") return S.corners.length ? S.corners.length + " corner" + (S.corners.length === 1 ? "" : "s") : "optional";
    if (k === "extras") return (S.references.length + S.landmarks.length) ? (S.references.length + S.landmarks.length) + " placed" : "optional";
    return "";
  }

  function renderPanel() {
    var ol = $("steps");
    ol.innerHTML = "";
    STEPS.forEach(function (s, i) {
      var li = document.createElement("li");
      var m = missing(s.key);
      var done = s.key === "save" ? false : (optional(s.key) ? stepState(i) !== "optional" && !m.length : !m.length);
      // four car points in the wrong order are not a done step (it showed a green tick)
      if (s.key === "car" && topNotAbove(S.axes)) done = false;
      li.className = (i === step ? "current " : "") + (done ? "done" : "");
      li.dataset.step = String(i);
      li.innerHTML = "<span class='num'>" + (done ? "&#10003;" : i + 1) + "</span><span>" + s.title +
        "</span><span class='state'>" + stepState(i) + "</span>";
      li.addEventListener("click", function () { goStep(i); });
      ol.appendChild(li);
    });
    var key = STEPS[step].key;
    var mapBox = $("map-box");
    if (!mapBox.hidden) {
      var before = key === "corners" ? $("checks") : $("help");
      if (mapBox.nextElementSibling !== before) {
        before.parentNode.insertBefore(mapBox, before);
        if (leafletMap) setTimeout(function () { leafletMap.invalidateSize(); }, 0);
      }
    }
    $("step-title").textContent = "Step " + (step + 1) + " of " + STEPS.length + ": " + STEPS[step].title;
    $("step-text").innerHTML = STEP_TEXT[key]();
    var miss = missing(key);
    var mEl = $("step-missing");
    if (miss.length) {
      mEl.className = "missing";
      mEl.textContent = (optional(key) ? "Optional; missing: " : "Still missing: ") + miss.join("; ") + ".";
    } else {
      mEl.className = "missing ok";
      mEl.textContent = key === "save" ? "Everything required is there." :
        (key === "car" ? "Done. Drag a point to adjust it, or go on with Next." : "Done. Go on with Next, or add more.");
    }
    if (key === "car" && carComplete() && topNotAbove(S.axes)) {
      // it said "Done." in green beside the red "Points in the wrong order?"
      mEl.className = "missing";
      mEl.textContent = "The four points are placed, but the top (point 4) is not above the " +
        "ground corner (point 1): drag them into this order, or undo and click them again.";
    }
    if (key === "car" && !carComplete()) {
      var next = AXIS_POINTS.filter(function (k) { return !S.axes[k]; })[0];
      mEl.textContent = "Next click (" + (AXIS_POINTS.indexOf(next) + 1) + " of 4): " + {
        origin: "the ground corner nearest the camera", length: "the far end of the length edge",
        width: "the far end of the width edge", height: "the top, straight above the first corner" }[next] + ".";
    }
    if (AXES.indexOf(key) >= 0 && pending) mEl.textContent = "Now click the other end of the line. " + mEl.textContent;
    renderForm(key);
    $("btn-prev").disabled = step === 0;
    $("btn-next").disabled = step === STEPS.length - 1;
    $("btn-undo").disabled = !undoStack.length && !pending;
    $("btn-redo").disabled = !redoStack.length;
    $("btn-save").textContent = config.mode === "crowd" ? "Submit" : "Save scene";
    var nBad = renderChecks();  // the red checks (a wrong corner, no focal length)
    if (key === "save" && !miss.length && nBad) {
      // it said "Everything required is there." in green beside a red "Wrong corner?"
      mEl.className = "missing";
      mEl.textContent = "Everything required is there, but " +
        (nBad === 1 ? "a check is red" : nBad + " checks are red") +
        " (under Checks, and over the photo): look at " + (nBad === 1 ? "it" : "them") +
        " before saving.";
    }
    var radios = document.querySelectorAll("input[name=xk]");
    Array.prototype.forEach.call(radios, function (r) {
      r.addEventListener("change", function () { extrasKind = r.value; });
    });
  }

  function esc(t) {
    return String(t).replace(/[&<>"']/g, function (c) {
      return { "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;" }[c];
    });
  }

  function renderForm(key) {
    var f = $("step-form");
    var h = "";
    if (key === "extras" && (S.references.length || S.landmarks.length)) {
      h += "<table>";
      S.references.forEach(function (r, i) {
        h += "<tr><td><b style='color:#1e7d3c'>P" + (i + 1) + "</b></td><td><input type='number' step='any' placeholder='latitude' data-ref='" + i + "' data-f='lat' value='" +
          (num(r.lat) ? r.lat : "") + "'></td><td><input type='number' step='any' placeholder='longitude' data-ref='" + i + "' data-f='lon' value='" +
          (num(r.lon) ? r.lon : "") + "'></td></tr>";
      });
      S.landmarks.forEach(function (l, i) {
        h += "<tr><td><b style='color:#b35c00'>B" + (i + 1) + "</b></td><td><input type='text' placeholder='building name' data-lm='" + i + "' data-f='name' value='" +
          esc(l.name || "") + "'></td><td><select data-lm='" + i + "' data-f='kind'><option value='building_corner'" + (l.kind === "building_corner" ? " selected" : "") +
          ">corner</option><option value='face_midpoint'" + (l.kind === "face_midpoint" ? " selected" : "") + ">face middle</option></select></td></tr>";
      });
      h += "</table>";
    } else if (key === "save") {
      var anns = base && base.annotations ? base.annotations : [];
      if (anns.length > 1) {
        h += "<label>This scene has " + anns.length + " annotators; you edit <select id='ann-pick'>" +
          anns.map(function (a, i) { return "<option value='" + i + "'" + (i === annIndex ? " selected" : "") + ">" + esc(a.annotator || "annotator " + (i + 1)) + "</option>"; }).join("") +
          "</select></label>";
      }
      h += "<label>Your name or id <input type='text' id='annotator' value='" + esc(S.annotator) + "' placeholder='anonymous'></label>";
      var cur = S.object ? (S.object.preset || "custom") : (base && base.object ? (base.object.preset || "scene") : "sedan");
      h += "<label>The car is a <select id='preset'>";
      if (base && base.object && !S.object) h += "<option value='scene' selected>as in the scene file</option>";
      Object.keys(PRESETS).forEach(function (p) {
        h += "<option value='" + p + "'" + (cur === p && (S.object || !(base && base.object)) ? " selected" : "") + ">" + p.replace("_", " ") +
          " (" + PRESETS[p].join(" × ") + " m)</option>";
      });
      h += "</select></label>";
      h += "<button type='button' id='btn-save-step' class='primary'>" +
        (config.mode === "crowd" ? "Submit my work" : "Save the scene file") + "</button>";
    }
    f.innerHTML = h;
    Array.prototype.forEach.call(f.querySelectorAll("input[data-ref]"), function (inp) {
      inp.addEventListener("change", function () {
        commit();
        var v = inp.value === "" ? null : Number(inp.value);
        S.references[Number(inp.dataset.ref)][inp.dataset.f] = v;
        changed(true);
      });
    });
    Array.prototype.forEach.call(f.querySelectorAll("[data-lm]"), function (inp) {
      inp.addEventListener("change", function () {
        commit();
        S.landmarks[Number(inp.dataset.lm)][inp.dataset.f] = inp.value;
        changed(true);
      });
    });
    var an = $("annotator");
    if (an) an.addEventListener("input", function () { S.annotator = an.value.trim(); });
    var pr = $("preset");
    if (pr) pr.addEventListener("change", function () {
      commit();
      S.object = pr.value === "scene" ? null : { preset: pr.value };
      changed(true);
    });
    var ss = $("btn-save-step");
    if (ss) {
      ss.disabled = !!(submitted || config.closed);  // crowd: submitted, or the task is full
      ss.addEventListener("click", save);
    }
    var ap = $("ann-pick");
    if (ap) ap.addEventListener("change", function () {
      base = buildScene();
      loadScene(base, Number(ap.value));
      goStep(6);
    });
  }

  var checkList = [];
  /* A check for the list; short: its shorter form over the photo (default: the same). */
  function check(cls, html, short) { checkList.push([cls, html, short || html]); return ""; }
  function fmt(x) { return Math.round(x).toLocaleString("en-US"); }

  function renderChecks() {
    var a = analysis;
    var h = "";
    checkList = [];
    AXES.forEach(function (k) {
      var n = S.lines[k].length;
      var vp = a.vps[k];
      var name = "<span class='swatch' style='background:" + COLOURS[k] + "'></span>" + k.charAt(0).toUpperCase() + k.slice(1) + " lines";
      if (n < 2) { h += check("info", name + ": " + n + " of 2 drawn"); return; }
      if (vp.error) { h += check("bad", name + ": " + vp.error + "."); return; }
      var tol = Math.max(2.0, 0.002 * DIAG);
      var where = vp.finite ? "meet at (" + fmt(vp.pixel[0]) + ", " + fmt(vp.pixel[1]) + ")" : "are parallel in the photo (they meet at infinity)";
      if (vp.rms > tol && n > 2) {
        var worst = 0;
        vp.residuals.forEach(function (r, i) { if (Math.abs(r) > Math.abs(vp.residuals[worst])) worst = i; });
        h += check("warn", "&#9888; " + name + " do not meet in one point (misfit " + vp.rms.toFixed(1) + " px): line " +
          k.charAt(0).toUpperCase() + (worst + 1) + " is probably not parallel to the others.");
      } else {
        h += check("ok", name + " " + where + ".");
      }
      // the car's own edge should point along the same vanishing direction
      var ax = S.axes;
      if (ax.origin && ax[k]) {
        var v = vp.homogeneous, o = ax.origin, s = [ax[k][0] - o[0], ax[k][1] - o[1]];
        var g = [v[0] - o[0] * v[2], v[1] - o[1] * v[2]];
        var c = Math.abs(g[0] * s[1] - g[1] * s[0]) / (Math.hypot(g[0], g[1]) * Math.hypot(s[0], s[1]) || 1);
        if (Math.hypot(s[0], s[1]) > 5 && c > Math.sin(12 * Math.PI / 180)) {
          h += check("warn", "&#9888; The car's " + k + " edge does not point where the " + k +
            " lines meet: are these lines along the car's " + k + "?");
        }
      }
    });
    // an axis resting on the car's own edges (calibrate's car-line warning, issue 24)
    CAR_LINE_AXES.forEach(function (k) {
      var cl = a.carLines[k];
      if (!cl || !cl.warn) return;
      var name = "<span class='swatch' style='background:" + COLOURS[k] + "'></span>" + k.charAt(0).toUpperCase() + k.slice(1) + " lines";
      var which = cl.n === 1 ? "the only one is on the car" : cl.nCar === cl.n ? "all " + cl.n + " on the car" :
        cl.nCar + " of " + cl.n + " on the car, the others shorter than its " + k + " edge";
      var head = "&#9888; " + name + " rest on the car's own edges (" + which + ")";
      h += check("warn", head + ": a rounded body's edges are curved silhouettes that bias the " + k +
        " direction and the focal length. Draw " + CAR_LINE_HINTS[k] + ", off the car and at least as long as its " +
        k + " edge (" + fmt(cl.edgePx) + " px).",
        head + ": draw " + CAR_LINE_HINTS[k] + ", off the car and at least " + fmt(cl.edgePx) + " px long.");
    });
    if (a.intrinsics) {
      var intr = a.intrinsics;
      if (intr.error) {
        h += check("bad", "&#9888; No focal length: " + esc(intr.error) + ". Check the lines of each axis.");
      } else {
        var hfov = 2 * Math.atan(W / 2 / intr.focal) * 180 / Math.PI;
        var ppw = intr.method === "orthocentre" ? "principal point where the three vanishing points put it (" +
          fmt(intr.principalPoint[0]) + ", " + fmt(intr.principalPoint[1]) + ")" : "principal point at the image centre";
        if (hfov < 5 || hfov > 140) {
          h += check("warn", "&#9888; Implied focal length " + fmt(intr.focal) + " px (field of view " + hfov.toFixed(0) +
            "&deg;) is implausible for a street camera: one set of lines is probably along the wrong axis.");
        } else {
          h += check("ok", "Focal length &asymp; " + fmt(intr.focal) + " px (horizontal field of view " + hfov.toFixed(0) + "&deg;); " + ppw + ".");
        }
      }
    }
    if (a.horizon) h += check("info", "The dashed light-blue line is the horizon: it should run at the camera's eye level, through distant street ends.");
    if (a.topBelow) {
      h += check("bad", "&#9888; Points in the wrong order? The <b>top</b> (point 4) is not above the first point. " +
        "Click in this order: 1 the car's ground corner nearest the camera, 2 the far end of its length edge, " +
        "3 the far end of its width edge, 4 its top straight above point 1 (drag the points or undo).",
        "&#9888; Points in the wrong order? The top (point 4) is not above point 1, the ground corner: drag them or undo.");
    }
    if (a.wrongCorner && !a.topBelow) {
      h += check("bad", "&#9888; Wrong corner? The " + a.wrongCorner + " end you clicked looks nearer to the camera than the " +
        "origin. Click the car's ground corner <b>nearest the camera</b> first (drag the points or undo).");
    }
    if (!checkList.length) check("info", "Checks appear here as you click.");
    // problems first, so they are seen without scrolling
    var rank = { bad: 0, warn: 1, ok: 2, info: 3 };
    checkList.sort(function (x, y) { return rank[x[0]] - rank[y[0]]; });
    $("checks-body").innerHTML = h + checkList.map(function (c) {
      return "<div class='check " + c[0] + "'>" + c[1] + "</div>";
    }).join("");
    var alerts = checkList.filter(function (c) { return c[0] === "bad" || c[0] === "warn"; });
    var al = $("alerts");
    al.innerHTML = alerts.map(function (c) { return "<div class='check " + c[0] + "'>" + c[2] + "</div>"; }).join("");
    al.hidden = !alerts.length;
    return alerts.filter(function (c) { return c[0] === "bad"; }).length;
  }

  function changed(keepForm) {
    selected = null;  // indices may have moved
    analysis = analyse(S, W, H, (base && base.camera) || {});
    render();
    if (keepForm) {
      // keep the focused input: update everything but the form
      var f = $("step-form"), html = f.innerHTML;
      var active = document.activeElement;
      renderPanelKeepForm(f, html, active);
    } else {
      renderPanel();
    }
    $("save-status").textContent = lastSaved && lastSaved !== JSON.stringify(buildScene()) ? "Changed since the last save." : ($("save-status").textContent || "");
    keepDraft();
  }

  // ------------------------------------------------------------------ unsaved work
  /* Work not yet saved or submitted is kept in this browser (localStorage, per photo and
     task) after every change, and restored when the page is opened again: a reload, the back
     button or a closed tab used to lose every click. Saving or submitting forgets it. */
  function fingerprint(text) {
    var h = 2166136261, stride = Math.max(1, Math.floor(text.length / 4096));
    for (var i = 0; i < text.length; i += stride) { h ^= text.charCodeAt(i); h = Math.imul(h, 16777619); }
    return (h >>> 0).toString(16) + ":" + text.length;
  }
  var DRAFT_KEY = "camloc-draft|" + [config.mode || "file", config.submitUrl || "", config.image.name, W, H,
    fingerprint(document.getElementById("camloc-image").textContent.trim()),
    // the scene the page opens with: another page of the same photo (a review of a scene)
    // never picks up this one's draft
    fingerprint(JSON.stringify(config.scene || null))].join("|");
  var pristine = null;    // this page's state (clicks) as it opened or was last saved/submitted
  function draftStore() { try { return window.localStorage || null; } catch (e) { return null; } }
  function unsaved() { return pristine !== null && snapshot() !== pristine; }
  function keepDraft() {
    var st = draftStore();
    if (!st || pristine === null) return;
    try {
      if (unsaved()) st.setItem(DRAFT_KEY, JSON.stringify({ state: S, base: base, step: step, saved: Date.now() }));
      else st.removeItem(DRAFT_KEY);
    } catch (e) { /* full or forbidden: the page works without it */ }
  }
  function markSaved() { pristine = snapshot(); keepDraft(); }
  function restoreDraft() {
    var st = draftStore(), d = null;
    if (!st) return false;
    try { d = JSON.parse(st.getItem(DRAFT_KEY) || "null"); } catch (e) { d = null; }
    var ok = d && d.state && d.state.axes && d.state.lines && Array.isArray(d.state.corners);
    if (!ok || JSON.stringify(d.state) === pristine) return false;
    if (d.base && validateScene(d.base)) return false;
    var before = snapshot();
    base = d.base || base;
    S = Object.assign(emptyState(), d.state);
    undoStack = [before];  // Undo goes back to the page as it opened
    redoStack = [];
    step = typeof d.step === "number" ? Math.max(0, Math.min(STEPS.length - 1, d.step)) : firstIncompleteStep();
    changed();
    var when = new Date(d.saved || Date.now());
    var msg = "Your unsaved work on this photo (" + when.toLocaleString() + ") was restored. " +
      (config.mode === "crowd" ? "Submit it when done" : "Save it when done") + "; Undo goes back to the page as it opened.";
    $("save-status").textContent = msg;
    flash(msg, true);
    return true;
  }
  window.addEventListener("beforeunload", function (e) {
    if (!unsaved()) return undefined;
    keepDraft();
    e.preventDefault();
    e.returnValue = "";  // the browser asks "Leave site? Changes you made may not be saved."
    return "";
  });
  function renderPanelKeepForm(f) {
    var saved = Array.prototype.slice.call(f.childNodes);
    renderPanel();
    f.innerHTML = "";
    saved.forEach(function (n) { f.appendChild(n); });
  }

  function goStep(i) {
    step = Math.max(0, Math.min(STEPS.length - 1, i));
    pending = null;
    changed();
  }

  var flashTimer = null;
  function flash(msg, ok) {
    var b = $("banner");
    b.textContent = msg;
    b.className = ok ? "ok" : "";
    b.hidden = false;
    clearTimeout(flashTimer);
    flashTimer = setTimeout(function () { b.hidden = true; }, ok ? 3000 : 5000);
  }
  function fatal(msg) {
    var b = $("banner");
    b.textContent = msg;
    b.className = "";
    b.hidden = false;
    clearTimeout(flashTimer);
  }

  // ------------------------------------------------------------------ save / submit
  var submitted = false;  // crowd mode: this page's work went in (one submission a page)
  function crowdDone(msg) {
    $("btn-save").disabled = true;
    $("save-status").textContent = msg;
  }
  /* A file name as one shell argument: a photo "la foto.JPG" saves "la foto.json", and the
   * hint "camloc calibrate la foto.json" ran calibrate on "la" (issue 24's graders copy it).
   * Double quotes work in sh, PowerShell and cmd; single quotes where double would not do. */
  function shellArg(name) {
    if (/^[A-Za-z0-9._+@%,:=\/-]+$/.test(name)) return name;
    if (!/["$`\\!]/.test(name)) return '"' + name + '"';
    return "'" + name.replace(/'/g, "'\\''") + "'";
  }

  function save() {
    var sc = buildScene();
    var miss = missing("save");
    var text = JSON.stringify(sc, null, 2) + "\n";
    if (config.mode === "crowd") {
      if (config.closed) { fatal(config.closed); return; }
      if (submitted) { flash("Already submitted: this page's work is in. Thank you! You can close the page."); return; }
      if (miss.length) { flash("Not yet: " + miss.join("; ") + "."); return; }
      $("save-status").textContent = "Submitting…";
      fetch(config.submitUrl, { method: "POST", headers: { "Content-Type": "application/json" }, body: text })
        .then(function (r) {
          return r.text().then(function (t) {
            if (!r.ok) throw new Error(t || ("HTTP " + r.status));
            lastSaved = JSON.stringify(sc);
            markSaved();
            submitted = true;
            crowdDone("Submitted. Thank you! Your work is in; you can close this page.");
            flash("Submitted. Thank you!", true);
          });
        })
        .catch(function (e) { $("save-status").textContent = "Not submitted: " + e.message; flash("Not submitted: " + e.message); });
      return;
    }
    var a = document.createElement("a");
    a.href = "data:application/json;charset=utf-8," + encodeURIComponent(text);
    a.download = (sc.id || "scene") + ".json";
    document.body.appendChild(a);
    a.click();
    a.remove();
    lastSaved = JSON.stringify(sc);
    markSaved();
    $("save-status").textContent = miss.length ?
      "Saved " + a.download + ", but incomplete: " + miss.join("; ") + "." :
      "Saved " + a.download + ". Check it with: camloc calibrate " + shellArg(a.download);
    flash(miss.length ? "Saved, but incomplete: " + miss.join("; ") + "." : "Saved " + a.download + ".", !miss.length);
  }

  function openSceneFile(file) {
    var reader = new FileReader();
    reader.onload = function () {
      var sc;
      try { sc = JSON.parse(reader.result); } catch (e) {
        var head = String(reader.result).replace(/^\s+/, "").slice(0, 100).toLowerCase();
        if (head.indexOf("<!doctype html") === 0 || head.indexOf("<html") === 0) {
          // this page itself, or another (it was "it is not JSON (Unexpected token '<'...)")
          fatal("Cannot open " + file.name + ": it is a web page (an annotation page?), not a " +
            "scene file: open the .json file that Save scene downloads.");
          return;
        }
        fatal("Cannot open " + file.name + ": it is not JSON (" + e.message + ")."); return;
      }
      var err = validateScene(sc);
      if (err) { fatal("Cannot open " + file.name + ": " + err + "."); return; }
      loadScene(sc, 0);
      lastSaved = JSON.stringify(buildScene());
      markSaved();  // what the file holds is saved already
      flash("Opened " + file.name + ": review the points, drag any that are off, then save.", true);
    };
    reader.onerror = function () { fatal("Cannot read " + file.name + "."); };
    reader.readAsText(file);
  }

  // ------------------------------------------------------------------ map
  function setupMap() {
    if (!mapIntersections().length || typeof L === "undefined") return;
    $("map-box").hidden = false;
    var map = L.map("map", { zoomControl: true, attributionControl: true });
    leafletMap = map;
    map.attributionControl.setPrefix(false);
    if (config.corners.attribution) map.attributionControl.addAttribution(esc(config.corners.attribution));
    var bounds = [];
    config.corners.features.forEach(function (f) {
      var g = f.geometry, p = f.properties || {};
      if (g.type === "LineString") {
        L.polyline(g.coordinates.map(function (c) { return [c[1], c[0]]; }), { color: "#8a94a0", weight: 5, opacity: 0.8 })
          .bindTooltip(esc(p.name || "street")).addTo(map);
      }
    });
    config.corners.features.forEach(function (f) {
      var g = f.geometry, p = f.properties || {};
      if (g.type !== "Point") return;
      var ll = [g.coordinates[1], g.coordinates[0]];
      if (p.kind === "corner") {
        bounds.push(ll);
        L.marker(ll, { icon: L.divIcon({ className: "", html: "<div class='corner-label'>" + (p.order + 1) + "</div>", iconSize: [22, 22], iconAnchor: [11, 11] }) })
          .bindTooltip("corner " + (p.order + 1) + ": " + esc((p.streets || []).join(" / "))).addTo(map);
      } else if (p.kind === "intersection") {
        bounds.push(ll);
        L.circleMarker(ll, { radius: 4, color: "#333", weight: 1, fillOpacity: 0.8 })
          .bindTooltip(esc((p.streets || []).join(" & "))).addTo(map);
      }
    });
    if (config.prior) {
      L.circleMarker([config.prior.lat, config.prior.lon], { radius: 6, color: "#1f6fd1", weight: 2, fillOpacity: 0.2 })
        .bindTooltip("the camera's listed location").addTo(map);
    }
    if (bounds.length) map.fitBounds(bounds, { padding: [18, 18], maxZoom: 19 });
    L.control.scale({ imperial: false }).addTo(map);
  }

  // ------------------------------------------------------------------ events
  canvas.addEventListener("pointerdown", function (e) {
    canvas.focus();
    var sp = eventPos(e);
    var t = e.button === 0 ? targetAt(sp[0], sp[1]) : null;
    if (t && !pending) {
      commit();
      drag = { target: t, start: sp, moved: false };
    } else {
      drag = { pan: true, start: sp, tx: view.tx, ty: view.ty, moved: false, button: e.button };
    }
    canvas.setPointerCapture(e.pointerId);
    e.preventDefault();
  });
  canvas.addEventListener("pointermove", function (e) {
    var sp = eventPos(e);
    mouseImg = toImage(sp[0], sp[1]);
    $("cursor-info").textContent = "x " + mouseImg[0].toFixed(1) + "  y " + mouseImg[1].toFixed(1) + "  zoom " + (view.scale * 100).toFixed(0) + "%";
    if (drag) {
      var moved = Math.hypot(sp[0] - drag.start[0], sp[1] - drag.start[1]);
      if (moved > 3) drag.moved = true;
      if (drag.pan && drag.moved) {
        view.tx = drag.tx + sp[0] - drag.start[0];
        view.ty = drag.ty + sp[1] - drag.start[1];
        canvas.classList.add("panning");
      } else if (drag.target && drag.moved) {
        setTarget(drag.target, mouseImg);
        drag.target.p = mouseImg;
        analysis = analyse(S, W, H, (base && base.camera) || {});
      }
      render();
      return;
    }
    var t = targetAt(sp[0], sp[1]);
    if ((t && t.p) !== (hover && hover.p) || !!t !== !!hover) { hover = t; }
    canvas.classList.toggle("over-point", !!hover);
    render();
  });
  canvas.addEventListener("pointerup", function (e) {
    var sp = eventPos(e);
    var d = drag;
    drag = null;
    canvas.classList.remove("panning");
    if (!d) return;
    if (d.target) {
      if (d.moved) { setTarget(d.target, toImage(sp[0], sp[1])); changed(); }
      else {
        undoStack.pop(); hover = d.target; selected = d.target; render();
        if (STEPS[step].key === "car" && !carComplete() && d.target.kind === "axis") {
          // a tap meant as the next car point but within 9 px of a placed one selected that
          // point, and nothing said why no point came (a car 30 px long on a phone's photo)
          var nextKey = AXIS_POINTS.filter(function (k) { return !S.axes[k]; })[0];
          var q = toScreen(d.target.p), away = Math.round(Math.hypot(q[0] - sp[0], q[1] - sp[1]));
          flash("That tap selected point " + (AXIS_POINTS.indexOf(d.target.key) + 1) + " (" +
            d.target.key + "), " + away + " px away, instead of placing point " +
            (AXIS_POINTS.indexOf(nextKey) + 1) + ": zoom in (+, or pinch) so the points stand " +
            "apart, then tap again.");
        }
      }
      return;
    }
    if (!d.moved && d.button === 0) place(toImage(sp[0], sp[1]));
  });
  canvas.addEventListener("pointerleave", function () { mouseImg = null; render(); });
  canvas.addEventListener("wheel", function (e) {
    e.preventDefault();
    var sp = eventPos(e);
    zoomAt(Math.exp(-e.deltaY * 0.0015), sp[0], sp[1]);
  }, { passive: false });
  canvas.addEventListener("contextmenu", function (e) { e.preventDefault(); });

  document.addEventListener("keydown", function (e) {
    var tag = (e.target && e.target.tagName) || "";
    if (tag === "INPUT" || tag === "SELECT" || tag === "TEXTAREA") return;
    var k = e.key, ctrl = e.ctrlKey || e.metaKey;
    if (ctrl && (k === "z" || k === "Z") && !e.shiftKey) { undo(); e.preventDefault(); }
    else if (ctrl && (k === "y" || ((k === "z" || k === "Z") && e.shiftKey))) { redo(); e.preventDefault(); }
    else if (ctrl && (k === "s" || k === "S")) { save(); e.preventDefault(); }
    else if (k === "Delete" || k === "Backspace") { if (hover) { deleteTarget(hover); e.preventDefault(); } }
    else if (k === "Escape") { pending = null; render(); renderPanel(); }
    else if (k === "Enter") { goStep(step + 1); e.preventDefault(); }
    else if (k === "PageUp") { goStep(step - 1); e.preventDefault(); }
    else if (k === "+" || k === "=") { var r = canvas.getBoundingClientRect(); zoomAt(1.25, r.width / 2, r.height / 2); }
    else if (k === "-" || k === "_") { var r2 = canvas.getBoundingClientRect(); zoomAt(0.8, r2.width / 2, r2.height / 2); }
    else if (k === "0") fit();
    else if (/^[1-7]$/.test(k) && !ctrl) goStep(Number(k) - 1);
  });
  $("btn-prev").addEventListener("click", function () { goStep(step - 1); });
  $("btn-next").addEventListener("click", function () { goStep(step + 1); });
  $("btn-undo").addEventListener("click", undo);
  $("btn-redo").addEventListener("click", redo);
  $("btn-save").addEventListener("click", save);
  $("btn-zoom-in").addEventListener("click", function () { var r = canvas.getBoundingClientRect(); zoomAt(1.25, r.width / 2, r.height / 2); });
  $("btn-zoom-out").addEventListener("click", function () { var r = canvas.getBoundingClientRect(); zoomAt(0.8, r.width / 2, r.height / 2); });
  $("btn-fit").addEventListener("click", fit);
  // a touch screen has no Delete key and no hover: tap a point, then this button
  // a warning over the photo is one line on a small screen: a tap shows it whole, another folds it
  $("alerts").addEventListener("click", function () { this.classList.toggle("open"); });
  $("btn-delete").addEventListener("click", function () {
    var t = selected || hover;
    if (t) deleteTarget(t);
    else flash("Tap or click a point of this step first (a line's end removes the line), then Delete.");
  });
  $("scene-file").addEventListener("change", function (e) {
    var f = e.target.files && e.target.files[0];
    if (f) openSceneFile(f);
    e.target.value = "";
  });
  window.addEventListener("resize", resize);

  // ------------------------------------------------------------------ start
  $("image-name").textContent = config.image.name + " — " + W + " × " + H + " px" +
    (config.mode === "crowd" ? " — crowd task" : "");
  photo.onload = function () { photoReady = true; document.body.dataset.ready = "1"; render(); };
  photo.onerror = function () {
    fatal("This browser cannot show the photo (" + config.image.name + "). Use a JPEG, PNG or WebP image.");
  };
  photo.src = document.getElementById("camloc-image").textContent.trim();
  resize();
  fit();
  if (config.scene) {
    var err = validateScene(config.scene);
    if (err) fatal("The scene cannot be used: " + err + ".");
    else { loadScene(config.scene, 0); lastSaved = JSON.stringify(buildScene()); }
  } else {
    changed();
  }
  pristine = snapshot();
  if (config.closed) {  // the task takes no more work: said before any click, not at Submit
    crowdDone(config.closed);
    fatal(config.closed);
  } else {
    restoreDraft();
  }
  try { setupMap(); } catch (e) { $("map-box").hidden = true; }
  renderPanel();

  /* Hooks for tests and for the service: read-only views and view control. */
  window.camloc = {
    state: function () { return clone(S); },
    scene: buildScene,
    step: function () { return step; },
    analysis: function () { return analysis; },
    screenFromImage: function (x, y) {
      var r = canvas.getBoundingClientRect(), q = toScreen([x, y]);
      return [q[0] + r.left, q[1] + r.top];
    },
    setView: function (scale, tx, ty) { view.scale = scale; view.tx = tx; view.ty = ty; render(); },
    fit: fit
  };
})();
