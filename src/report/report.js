// gyrocal report: the page's driver (docs/report.md). It reads the plot descriptions that the C++ side wrote
// (src/report/charts.hpp: one kind per builder below), hands each to Chart.js with animation off, and records
// in <body data-plots-rendered> how many were drawn with marks and ink. Compiled into gyrocal by
// src/report/embed_file.cmake and inlined into every report.
(function () {
  'use strict';
  var record = window.gyrocalRecordError;
  var body = document.body;
  var specs = [];
  try {
    specs = JSON.parse(document.getElementById('gyrocal-plots').textContent);
  } catch (e) {
    record('plot descriptions: ' + e.message);
  }
  body.setAttribute('data-plots-expected', String(specs.length));
  body.setAttribute('data-plots-rendered', '0');
  if (typeof Chart === 'undefined') {
    record('Chart.js is not available');
    return;
  }
  Chart.defaults.animation = false;
  Chart.defaults.responsive = true;
  Chart.defaults.maintainAspectRatio = false;
  Chart.defaults.color = '#222';
  Chart.defaults.font.family = 'system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif';

  function title(text) { return { display: !!text, text: text || '' }; }
  function fixedTicks(values) {
    return function (axis) { axis.ticks = values.map(function (v) { return { value: v }; }); };
  }
  function zeroLine(c) { return c.tick && c.tick.value === 0 ? '#555' : 'rgba(0,0,0,0.1)'; }

  var builders = {
    // A value with an error bar per category: the bar is a floating bar [low, high], the value a point.
    errorbar: function (s) {
      return {
        type: 'bar',
        data: {
          labels: s.labels,
          datasets: [
            { type: 'line', label: s.center_label, data: s.center, showLine: false, pointRadius: 4,
              pointHoverRadius: 6, borderColor: '#b2182b', backgroundColor: '#b2182b', order: 0 },
            { type: 'bar', label: s.band_label, order: 1, grouped: false, barPercentage: 0.3, categoryPercentage: 1,
              data: s.low.map(function (lo, i) { return lo === null || s.high[i] === null ? null : [lo, s.high[i]]; }),
              backgroundColor: 'rgba(33,102,172,0.25)', borderColor: '#2166ac', borderWidth: 1 }
          ]
        },
        options: {
          plugins: {
            legend: { position: 'bottom' },
            tooltip: { callbacks: { label: function (c) { return s.tips[c.dataIndex]; } } }
          },
          scales: { x: { title: title(s.xlabel) }, y: { title: title(s.ylabel), grid: { color: zeroLine } } }
        }
      };
    },
    // A heat map as horizontal floating bars: one dataset per column j spanning [j, j + 1] in every row,
    // each cell coloured by its own value.
    heatmap: function (s) {
      var n = s.cols.length;
      return {
        type: 'bar',
        data: {
          labels: s.rows,
          datasets: s.cols.map(function (col, j) {
            return { label: col, grouped: false, barPercentage: 1, categoryPercentage: 1,
                     data: s.rows.map(function () { return [j, j + 1]; }),
                     backgroundColor: s.rows.map(function (r, i) { return s.colours[i][j]; }),
                     borderColor: '#ffffff', borderWidth: 1, borderSkipped: false };
          })
        },
        options: {
          indexAxis: 'y',
          plugins: {
            legend: { display: false },
            tooltip: { callbacks: {
              title: function (items) { return s.rows[items[0].dataIndex] + ' \u2192 ' + s.cols[items[0].datasetIndex]; },
              label: function (c) { return s.tips[c.dataIndex][c.datasetIndex]; } } }
          },
          scales: {
            x: { type: 'linear', min: 0, max: n, position: 'top', grid: { display: false }, title: title(s.xlabel),
                 afterBuildTicks: fixedTicks(s.cols.map(function (c, j) { return j + 0.5; })),
                 ticks: { autoSkip: false, maxRotation: 60, callback: function (v) { return s.cols[Math.floor(v)]; } } },
            y: { grid: { display: false }, ticks: { autoSkip: false }, title: title(s.ylabel) }
          }
        }
      };
    },
    histogram: function (s) {
      return {
        type: 'bar',
        data: { labels: s.labels, datasets: [{ label: s.title, data: s.counts, barPercentage: 1, categoryPercentage: 1,
                backgroundColor: 'rgba(33,102,172,0.6)', borderColor: '#2166ac', borderWidth: 1 }] },
        options: {
          plugins: {
            legend: { display: false }, title: { display: true, text: s.title },
            tooltip: { callbacks: { title: function (items) { return s.tips[items[0].dataIndex]; },
                                    label: function (c) { return c.parsed.y + ' trials'; } } }
          },
          scales: { x: { title: title(s.xlabel), ticks: { maxTicksLimit: 5, maxRotation: 0, autoSkipPadding: 20 } },
                    y: { title: title(s.ylabel), beginAtZero: true } }
        }
      };
    },
    stacked: function (s) {
      return {
        type: 'bar',
        data: { labels: s.labels, datasets: s.series.map(function (x) {
          return { label: x.name, data: x.values, backgroundColor: x.colour };
        }) },
        options: {
          plugins: {
            legend: { position: 'right' },
            tooltip: { callbacks: { label: function (c) { return c.dataset.label + ': ' + c.parsed.y.toFixed(1) + ' %'; } } }
          },
          scales: { x: { stacked: true, title: title(s.xlabel) },
                    y: { stacked: true, min: 0, max: s.ymax, title: title(s.ylabel) } }
        }
      };
    },
    // Both axes logarithmic: measured points with error bars (a line through [x, low] and [x, high], broken by
    // a gap after each bar) and model lines through their points.
    loglog: function (s) {
      var bars = [];
      s.points.forEach(function (p, i) {
        if (s.low[i] === null || s.high[i] === null) return;
        bars.push({ x: p.x, y: s.low[i] }, { x: p.x, y: s.high[i] }, { x: p.x, y: null });
      });
      var datasets = [
        { label: s.points_label, data: s.points, showLine: false, pointRadius: 4, pointHoverRadius: 6,
          borderColor: '#b2182b', backgroundColor: '#b2182b', order: 0 },
        { label: s.bars_label, data: bars, showLine: true, spanGaps: false, pointRadius: 0, pointHitRadius: 0,
          borderColor: 'rgba(178,24,43,0.55)', borderWidth: 2, order: 1 }
      ];
      s.lines.forEach(function (l) {
        datasets.push({ label: l.name, data: l.points, showLine: true, pointRadius: 0, pointHitRadius: 0,
                        borderColor: l.colour, backgroundColor: l.colour, borderWidth: 2,
                        borderDash: l.dash ? [6, 4] : [], order: 2 });
      });
      return {
        type: 'scatter',
        data: { datasets: datasets },
        options: {
          plugins: {
            legend: { position: 'bottom' },
            tooltip: { filter: function (c) { return c.datasetIndex === 0; },
                       callbacks: { label: function (c) { return s.tips[c.dataIndex]; } } }
          },
          scales: { x: { type: 'logarithmic', title: title(s.xlabel) },
                    y: { type: 'logarithmic', title: title(s.ylabel) } }
        }
      };
    },
    // A control chart against the date (x in days since 1970-01-01 UTC, written as dates): each run's value
    // (flagged runs as red triangles) with its error bar (a broken line, as loglog's), the mean, the Shewhart
    // limits, and the EWMA with its limits per run (EWMA points that left them larger).
    control: function (s) {
      var x0 = Infinity, x1 = -Infinity;
      s.points.forEach(function (p) { x0 = Math.min(x0, p.x); x1 = Math.max(x1, p.x); });
      var pad = x1 > x0 ? (x1 - x0) * 0.04 : 1;
      x0 -= pad; x1 += pad;
      var span = x1 - x0;
      function date(v) {
        var t = new Date(v * 86400000);
        if (isNaN(t.getTime())) return String(v);
        var iso = t.toISOString();
        return span < 4 ? iso.slice(0, 10) + ' ' + iso.slice(11, 16) : iso.slice(0, 10);
      }
      var bars = [];
      s.points.forEach(function (p, i) {
        if (s.low[i] === null || s.high[i] === null) return;
        bars.push({ x: p.x, y: s.low[i] }, { x: p.x, y: s.high[i] }, { x: p.x, y: null });
      });
      var red = '#d62728', blue = '#2166ac', orange = '#e08214';
      var datasets = [
        { label: 'runs (value \u00b1 \u03c3)', data: s.points, tips: s.tips, showLine: false, order: 0,
          pointStyle: s.flagged.map(function (f) { return f ? 'triangle' : 'circle'; }),
          pointRadius: s.flagged.map(function (f) { return f ? 7 : 4; }), pointHoverRadius: 8,
          borderColor: s.flagged.map(function (f) { return f ? red : blue; }),
          backgroundColor: s.flagged.map(function (f) { return f ? red : blue; }) },
        { label: '\u03c3 of each run', data: bars, showLine: true, spanGaps: false, pointRadius: 0, pointHitRadius: 0,
          borderColor: 'rgba(33,102,172,0.5)', borderWidth: 2, order: 1 }
      ];
      if (s.mean !== null)
        datasets.push({ label: s.mean_label, data: [{ x: x0, y: s.mean }, { x: x1, y: s.mean }], showLine: true,
                        pointRadius: 0, pointHitRadius: 0, borderColor: '#1f2328', borderWidth: 1.5, order: 2 });
      if (s.limits !== null)
        datasets.push({ label: 'Shewhart limits', showLine: true, spanGaps: false, pointRadius: 0, pointHitRadius: 0,
                        data: [{ x: x0, y: s.limits[1] }, { x: x1, y: s.limits[1] }, { x: x1, y: null },
                               { x: x0, y: s.limits[0] }, { x: x1, y: s.limits[0] }],
                        borderColor: red, borderWidth: 1.5, borderDash: [6, 4], order: 3 });
      if (s.ewma.length > 0) {
        datasets.push({ label: 'EWMA', data: s.ewma, tips: s.ewma_tips, showLine: true, order: 4,
                        pointRadius: s.ewma_flagged.map(function (f) { return f ? 6 : 2; }),
                        pointStyle: s.ewma_flagged.map(function (f) { return f ? 'rectRot' : 'circle'; }),
                        borderColor: orange, backgroundColor: orange, borderWidth: 1.5 });
        var lim = [];
        s.ewma.forEach(function (p, i) { lim.push({ x: p.x, y: s.ewma_high[i] }); });
        lim.push({ x: s.ewma[s.ewma.length - 1].x, y: null });
        s.ewma.forEach(function (p, i) { lim.push({ x: p.x, y: s.ewma_low[i] }); });
        datasets.push({ label: 'EWMA limits', data: lim, showLine: true, spanGaps: false, pointRadius: 0,
                        pointHitRadius: 0, borderColor: orange, borderWidth: 1, borderDash: [2, 3], order: 5 });
      }
      return {
        type: 'scatter',
        data: { datasets: datasets },
        options: {
          plugins: {
            title: title(s.title),
            legend: { position: 'bottom', labels: { boxWidth: 14, font: { size: 11 } } },
            tooltip: { filter: function (c) { return !!c.dataset.tips; },
                       callbacks: { title: function () { return ''; },
                                    label: function (c) { return c.dataset.tips[c.dataIndex]; } } }
          },
          scales: {
            x: { type: 'linear', min: x0, max: x1,
                 ticks: { maxTicksLimit: 6, maxRotation: 0, callback: function (v) { return date(v); } } },
            y: { title: title(s.ylabel) }
          }
        }
      };
    },
    scatter: function (s) {
      return {
        type: 'scatter',
        data: { datasets: s.series.map(function (x) {
          return { label: x.name, data: x.points, backgroundColor: x.colour, borderColor: x.colour,
                   pointRadius: 6, pointHoverRadius: 8 };
        }) },
        options: {
          plugins: {
            legend: { position: 'bottom' },
            tooltip: { callbacks: { label: function (c) { return s.series[c.datasetIndex].tips[c.dataIndex]; } } }
          },
          scales: {
            x: { type: 'linear', min: s.xmin, max: s.xmax, title: title(s.xlabel),
                 afterBuildTicks: s.xticks ? fixedTicks(s.xticks) : undefined },
            y: { type: 'linear', min: s.ymin, max: s.ymax, title: title(s.ylabel),
                 afterBuildTicks: s.yticks ? fixedTicks(s.yticks) : undefined }
          }
        }
      };
    }
  };

  // True when the canvas holds ink: the plot was drawn, not just laid out.
  function inked(canvas) {
    var w = canvas.width, h = canvas.height;
    if (!w || !h) return false;
    var px = canvas.getContext('2d').getImageData(0, 0, w, h).data, n = 0;
    for (var i = 3; i < px.length; i += 4) if (px[i] !== 0 && ++n > 200) return true;
    return false;
  }

  // Folded parts (<details class="fold">) are opened while the plots are drawn and the tables measured, so
  // that a plot inside one gets its size and a table inside one is measured as it shows when opened; the
  // folds closed before are closed again afterwards, and every fold is open on paper.
  var folds = Array.prototype.slice.call(document.querySelectorAll('details.fold'));
  var closed = folds.filter(function (d) { return !d.open; });
  folds.forEach(function (d) { d.open = true; });

  var charts = [], rendered = 0;
  specs.forEach(function (s) {
    try {
      var canvas = document.getElementById(s.id);
      if (!canvas) throw new Error('no canvas');
      if (!builders[s.kind]) throw new Error('unknown kind of plot ' + s.kind);
      var chart = new Chart(canvas, builders[s.kind](s));
      charts.push(chart);
      var marks = 0;
      chart.data.datasets.forEach(function (d, i) { marks += chart.getDatasetMeta(i).data.length; });
      canvas.setAttribute('data-marks', String(marks));
      if (marks === 0) throw new Error('nothing to draw');
      if (!inked(canvas)) throw new Error('the canvas stayed blank');
      rendered += 1;
    } catch (e) {
      record('plot ' + s.id + ': ' + (e && e.message ? e.message : e));
    }
  });
  body.setAttribute('data-plots-rendered', String(rendered));
  // Tables wider than their box (which then scrolls sideways): how many, for the checks on the page's width.
  var wide = 0;
  Array.prototype.forEach.call(document.querySelectorAll('.table-wrap'), function (w) {
    if (w.scrollWidth > w.clientWidth + 1) wide += 1;
  });
  body.setAttribute('data-wide-tables', String(wide));
  body.setAttribute('data-page-overflow', String(document.documentElement.scrollWidth > window.innerWidth));
  closed.forEach(function (d) { d.open = false; });
  body.setAttribute('data-folds', String(folds.length));
  // Charts size themselves to their boxes; the printed page has other boxes, and shows every fold open.
  var closedForPrint = [];
  window.addEventListener('beforeprint', function () {
    closedForPrint = folds.filter(function (d) { return !d.open; });
    closedForPrint.forEach(function (d) { d.open = true; });
    charts.forEach(function (c) { c.resize(); });
  });
  window.addEventListener('afterprint', function () {
    closedForPrint.forEach(function (d) { d.open = false; });
    charts.forEach(function (c) { c.resize(); });
  });
})();
