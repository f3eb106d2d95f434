/* The report page's one script (crosscheck/report/static/report.js), inlined into every page by
   crosscheck/report/style.py. It judges, ranks and formats nothing: every number reaches it
   already written by crosscheck/report/text.py, every verdict and rank by the Python rules.
   It unpacks the packed payloads, frames wide tables, draws the charts lazily, shows the
   results table, the case details and the coverage grids, and writes the advise form's
   command. Its one global is window.crosscheck. */
(function () {
  "use strict";
  var cc = window.crosscheck = {};

  /* Packed payloads (gzip + base64 in <script type="application/octet-stream">) are unpacked
     with the browser's DecompressionStream: no network. unpack(id) resolves to the text. */
  cc.unpackText = function (base64) {
    var bytes = Uint8Array.from(atob(base64), function (c) { return c.charCodeAt(0); });
    var stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("gzip"));
    return new Response(stream).text();
  };
  cc.unpack = function (id) {
    return cc.unpackText(document.getElementById(id).textContent.trim());
  };
  function ready(fn) {
    if (document.readyState === "loading") { document.addEventListener("DOMContentLoaded", fn); } else { fn(); }
  }
  function esc(text) {
    return String(text).replace(/[&<>"']/g, function (c) {
      return {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;"}[c];
    });
  }

  /* Every table wider than its box scrolls inside a .wide box framed by a .wide-frame, whose cue
     says how many columns are cut off on each side (a click scrolls there) and whose fade marks
     the cut edge. Tables of the page and those built later (case details) are wrapped as they
     appear; the results table (DataTables) scrolls in its own layout cell, which is framed once
     the table marks it .wide (and its cue is updated on every draw). */
  (function () {
    function hidden(box) {
      var head = box.querySelector("thead tr:last-child") || box.querySelector("tr");
      var edge = box.getBoundingClientRect(), left = 0, right = 0;
      if (!head) { return [0, 0]; }
      Array.prototype.forEach.call(head.cells, function (cell) {
        var r = cell.getBoundingClientRect();
        if (getComputedStyle(cell).position === "sticky") { return; }
        if (r.right > edge.right + 1) { right += cell.colSpan; }
        else if (r.left < edge.left - 1) { left += cell.colSpan; }
      });
      return [left, right];
    }
    function columns(n) { return n + (n === 1 ? " more column" : " more columns"); }
    function update(frame) {
      var box = frame.querySelector(":scope > .wide"), cue = frame.querySelector(":scope > .cue");
      if (!box || !(box.checkVisibility ? box.checkVisibility() : box.offsetParent)) { return; }
      var cut = hidden(box), clipped = box.scrollWidth > box.clientWidth + 1;
      frame.classList.toggle("clipped", clipped);
      frame.classList.toggle("more-left", clipped && box.scrollLeft > 1);
      frame.classList.toggle("more-right", clipped && box.scrollLeft + box.clientWidth < box.scrollWidth - 1);
      var held = box.querySelector("tbody td:first-child"), fade = frame.querySelector(":scope > .fade.left");
      fade.style.left = held && getComputedStyle(held).position === "sticky" ? held.offsetWidth + "px" : "0";
      frame.dataset.hiddenLeft = cut[0];
      frame.dataset.hiddenRight = cut[1];
      cue.children[0].textContent = cut[0] ? "\u2190 " + columns(cut[0]) : "";
      cue.children[1].textContent = cut[1] ? columns(cut[1]) + " \u2192 (scroll sideways)" : "";
    }
    function frame(box) {
      if (box.parentElement.classList.contains("wide-frame")) { return box.parentElement; }
      var outer = document.createElement("div"), cue = document.createElement("div");
      outer.className = "wide-frame";
      cue.className = "cue";
      cue.innerHTML = '<a class="cue-left"></a><a class="cue-right"></a>';
      cue.children[0].onclick = function () { box.scrollBy({left: -0.8 * box.clientWidth, behavior: "smooth"}); };
      cue.children[1].onclick = function () { box.scrollBy({left: 0.8 * box.clientWidth, behavior: "smooth"}); };
      box.parentElement.insertBefore(outer, box);
      outer.appendChild(cue);
      outer.appendChild(box);
      ["left", "right"].forEach(function (side) {
        var fade = document.createElement("div");
        fade.className = "fade " + side;
        outer.appendChild(fade);
      });
      box.addEventListener("scroll", function () { update(outer); }, {passive: true});
      if ("ResizeObserver" in window) {  /* columns shown or hidden, a fold opened, a new width */
        var table = box.querySelector("table");
        new ResizeObserver(function () { update(outer); }).observe(table || box);
      }
      return outer;
    }
    function wrap(root) {
      Array.prototype.forEach.call(root.querySelectorAll("table"), function (table) {
        var box = table.closest(".wide");
        if (table.id === "results-table" || table.closest(".dt-container")) {  /* its own box */
          if (box) { update(frame(box)); }
          return;
        }
        if (!box) {
          box = document.createElement("div");
          box.className = "wide";
          table.parentElement.insertBefore(box, table);
          box.appendChild(table);
        }
        update(frame(box));
      });
    }
    function updateAll() { document.querySelectorAll(".wide-frame").forEach(update); }
    cc.wideTables = function () {
      wrap(document.body);
      updateAll();
    };
    ready(function () {
      cc.wideTables();
      new MutationObserver(function (changes) {
        changes.forEach(function (c) {
          c.addedNodes.forEach(function (n) { if (n.nodeType === 1 && !n.closest(".wide-frame > .cue")) { wrap(n.tagName === "TABLE" ? n.parentElement : n); } });
        });
      }).observe(document.body, {childList: true, subtree: true});
      document.addEventListener("toggle", updateAll, true);
      window.addEventListener("resize", updateAll);
    });
  })();

  /* Each chart is a <div class="plotly-graph-div"> followed by its figure, packed in a
     <script class="plotly-figure"> (crosscheck/report/style.py plot_div). A chart is drawn once
     plotly.js is unpacked and loaded and the chart comes near the viewport; after the load
     event the visible charts not yet drawn are drawn one at a time in idle time.
     drawAllCharts() draws every chart now and resolves when all are drawn. */
  (function () {
    var loading = null, waiting = [];
    cc.plotlyReady = function () {
      if (!loading) {
        loading = cc.unpack("plotly-js").then(function (text) {
          var script = document.createElement("script");
          script.textContent = text;
          document.head.appendChild(script);
          document.documentElement.dataset.plotly = "loaded";
          return window.Plotly;
        });
      }
      return loading;
    };
    function plot(div, figure) {
      return function (Plotly) {
        return cc.unpackText(figure.textContent.trim()).then(function (text) {
          var content = JSON.parse(text);
          return Plotly.newPlot(div, content.data, content.layout, JSON.parse(figure.dataset.config));
        });
      };
    }
    function draw(div) {
      if (!div.drawChart) { return div.drawn || Promise.resolve(); }
      var fn = div.drawChart;
      div.drawChart = null;
      div.drawn = cc.plotlyReady().then(fn).catch(function (e) { console.error(e); });
      return div.drawn;
    }
    cc.drawAllCharts = function () { return Promise.all(waiting.map(draw)); };
    ready(function () {
      var near = "IntersectionObserver" in window ? new IntersectionObserver(function (entries) {
        entries.forEach(function (e) { if (e.isIntersecting) { near.unobserve(e.target); draw(e.target); } });
      }, {rootMargin: "300px"}) : null;
      document.querySelectorAll("script.plotly-figure").forEach(function (figure) {
        var div = figure.previousElementSibling;
        div.drawChart = plot(div, figure);
        waiting.push(div);
        if (near) { near.observe(div); } else { draw(div); }
      });
    });
    /* A chart inside a closed <details> is drawn when the details opens (by then it has a
       width), and one drawn while hidden (drawAllCharts) is resized to its box then. */
    document.addEventListener("toggle", function (event) {
      if (!event.target.open) { return; }
      event.target.querySelectorAll(".plotly-graph-div").forEach(function (div) {
        draw(div).then(function () { if (window.Plotly) { window.Plotly.Plots.resize(div); } });
      });
    }, true);
    window.addEventListener("load", function () {
      var idle = window.requestIdleCallback || function (f) { return setTimeout(f, 50); };
      (function next() {
        var div = waiting.filter(function (d) { return d.drawChart && d.offsetParent; })[0];
        if (div) { idle(function () { draw(div).then(next); }); }
      })();
    });
  })();

  /* A word for a POSIX shell, quoted as Python's shlex.quote does (crosscheck/report/repro_links.py). */
  function shellWord(text) {
    text = String(text);
    if (text === "") { return "''"; }
    return /[^\w@%+=:,.\/-]/.test(text) ? "'" + text.replace(/'/g, "'\"'\"'") + "'" : text;
  }
  /* The command that prints the repro script of a case on an engine, as repro_links.command writes it. */
  cc.reproCommand = function (run, caseId, engine) {
    return ["crosscheck", "repro", run, caseId, "--engine", engine].map(shellWord).join(" ");
  };
  /* A pair's repro: a link to its script when the run folder holds it (link), and its command
     in a fold (a <code> to copy). */
  function reproHtml(run, caseId, engine, link) {
    var title = "standalone script reproducing this case on " + engine;
    return (link ? '<a class="repro" href="' + esc(link) + '" title="' + esc(title) + '">repro</a> ' : "") +
      '<details class="repro-command"><summary title="' + esc("the command that prints the " + title) + '">' +
      (link ? "command" : "repro") + "</summary><code>" + esc(cc.reproCommand(run, caseId, engine)) + "</code></details>";
  }

  /* The results table (crosscheck/report/results_table.py): one row per case x engine, its
     statuses judged and its errors written in Python (a column sorts by the number the text
     reads back; a status by its severity, from the data). */
  function resultsTable(data, DataTable) {
    var SEVERITY = data.severity;
    var table = document.getElementById("results-table"), idChars = Number(table.dataset.idChars);
    function cut(text, n) { return text.length > n ? text.slice(0, n - 1) + "\u2026" : text; }
    /* A long case id cut in the middle: its start and its end (the time step, the twin) stay. */
    function middle(text, n) {
      var head = Math.ceil((n - 1) / 2);
      return text.length > n ? text.slice(0, head) + "\u2026" + text.slice(text.length - (n - 1 - head)) : text;
    }
    /* The badge of a pair that answered differently when asked again (the repeat check): the
       quantities that changed, both answers, in its hover. */
    function again(row) {
      var lines = Object.keys(row.again).filter(function (q) {
        return row.q[q][0] !== row.again[q][0] || row.q[q][3] !== row.again[q][1];
      }).map(function (q) {
        return q + ": " + row.q[q][3] + " (" + row.q[q][0] + "), asked again: " + row.again[q][1] + " (" + row.again[q][0] + ")";
      });
      return ' <span class="badge-nondeterministic" title="answered differently in a fresh worker\n' + esc(lines.join("\n")) + '">nondeterministic</span>';
    }
    function sortable(text) { return text ? parseFloat(text) : NaN; }
    function nanLast(sign) {
      return function (a, b) {
        var na = typeof a !== "number" || isNaN(a), nb = typeof b !== "number" || isNaN(b);
        if (na || nb) { return na === nb ? 0 : (na ? 1 : -1); }
        return sign * (a - b);
      };
    }
    DataTable.ext.type.order["nanlast-asc"] = nanLast(1);
    DataTable.ext.type.order["nanlast-desc"] = nanLast(-1);
    var cases = data.cases;
    var columns = [
      {data: "case", className: "case", render: function (c, type, row) {
        var id = cases[c].id;
        if (type !== "display") { return id; }
        var links = row.twins.map(function (t) {
          return '<a class="twin" href="#case-' + esc(cases[t].id) + '" title="swapped twin, same verdicts">&#8644; twin</a>';
        });
        if (cases[c].twin_of) { links.push('<span title="a swapped twin whose verdicts differ from its original\'s">&ne; its original</span>'); }
        if (row.repro || row.breaking) { links.push(reproHtml(data.run, id, row.engine, row.repro)); }
        var html = '<a class="case-id" href="#case-' + esc(id) + '" title="' + esc(id) + '">' + esc(middle(id, idChars)) + "</a>";
        return links.length ? html + '<br><small class="links">' + links.join(" ") + "</small>" : html;
      }},
      {data: "engine", render: function (e, type) { return type === "display" ? esc(e) : e; }},
      {data: "case", render: function (c) { return esc(cases[c].kind); }},
      {data: "case", render: function (c) { return esc(cases[c].group); }},
      {data: "status", render: function (s, type, row) {
        if (type === "sort" || type === "type") { return SEVERITY[s]; }
        if (type !== "display") { return row.again ? s + " nondeterministic" : s; }
        return '<span class="' + esc(s) + '">' + esc(s) + "</span>" + (row.again ? again(row) : "");
      }},
      {data: "error", type: "nanlast", className: "num", render: function (e, type) {
        return type === "sort" || type === "type" ? sortable(e) : esc(e);
      }}
    ];
    data.quantities.forEach(function (q) {
      columns.push({data: null, type: "nanlast", orderSequence: ["desc", "asc"], render: function (d, type, row) {
        var v = row.q[q];
        if (type === "sort" || type === "type") { return v ? sortable(v[2]) : NaN; }
        if (!v) { return ""; }
        if (type !== "display") { return v[0] + " " + v[1]; }
        return '<span class="' + esc(v[0]) + '">' + esc(v[0]) + "</span>" + (v[1] ? " " + esc(v[1]) : "") +
          (v[2] && v[0] !== "agree" ? " <small>" + esc(v[2]) + "</small>" : "") +
          (v[3] ? '<br><span class="mono" title="' + esc(v[3]) + '">' + esc(cut(v[3], 24)) + "</span>" : "");
      }});
    });
    var breaking = document.getElementById("results-breaking");
    var every = document.getElementById("results-every-column");
    var FIRST = columns.length - data.quantities.length;
    var dt = new DataTable(table, {
      data: data.rows.filter(function (r) { return !r.folded; }),
      columns: columns, order: [[4, "asc"], [5, "desc"]], deferRender: true, autoWidth: false,
      pageLength: 10, lengthMenu: [10, 25, 50, 100, 500],
      columnControl: [{target: 1, content: ["search"]}],
      language: {info: "showing _START_ to _END_ of _TOTAL_ rows",
                 infoFiltered: "(filtered from _MAX_)", infoEmpty: "showing 0 rows"}
    });
    table.parentElement.classList.add("wide");  /* wider than its box: it scrolls sideways there */
    dt.on("draw", function () { cc.wideTables(); });  /* with its cue */
    cc.wideTables();
    dt.search.fixed("breaking", function (text, row) {
      return !breaking.checked || row.breaking;
    });
    breaking.addEventListener("change", function () { dt.draw(); });
    /* A quantity's column shows while a row on the page has it (or one is filtering by it). */
    var fitting = false;
    function fitColumns() {
      var rows = dt.rows({page: "current"}).data().toArray();
      if (fitting || !rows.length) { return; }
      fitting = true;
      var changed = false;
      data.quantities.forEach(function (q, i) {
        var column = dt.column(FIRST + i);
        var want = every.checked || column.search() !== "" ||
          rows.some(function (r) { return q in r.q; });
        if (column.visible() !== want) { column.visible(want, false); changed = true; }
      });
      if (changed) { dt.columns.adjust(); cc.wideTables(); }  /* the cue counts them too */
      fitting = false;
    }
    dt.on("draw", fitColumns);
    every.addEventListener("change", fitColumns);
    dt.draw();
    table.dataset.ready = "1";
    cc.resultsTable = dt;
  }

  /* A case's details, built from the results data when a case link (#case-<id>) is followed. */
  function caseDetails(data) {
    var byId = {}, rowsOf = {};
    data.cases.forEach(function (c, i) { byId[c.id] = i; rowsOf[i] = []; });
    data.rows.forEach(function (r) { rowsOf[r.case].push(r); });
    var list = document.getElementById("case-ids");
    list.innerHTML = data.cases.map(function (c) { return '<option value="' + esc(c.id) + '">'; }).join("");
    var input = document.getElementById("case-open");
    input.addEventListener("change", function () {
      if (input.value in byId) { location.hash = "#case-" + input.value; }
    });
    function build(i) {
      var c = data.cases[i], rows = rowsOf[i];
      var body = rows.map(function (r) {
        var time = r.time === null ? "&ndash;" : esc(r.time);
        return Object.keys(r.q).map(function (q) {
          var v = r.q[q];
          return "<tr><td>" + esc(r.engine) + "</td><td>" + esc(q) + '</td><td class="mono">' + esc(v[3]) +
            '</td><td class="mono">' + esc(v[4]) + '</td><td class="num">' + esc(v[2]) +
            '</td><td class="num">' + esc(v[5]) + '</td><td class="' + esc(v[0]) + '">' + esc(v[0]) +
            "</td><td>" + esc(v[1]) + "</td><td>" + esc(v[6]) + '</td><td class="num">' + time + "</td></tr>";
        }).join("");
      }).join("");
      var twin = c.twin_of ? ' &middot; swapped twin of <a href="#case-' + esc(c.twin_of) + '">' + esc(c.twin_of) + "</a>" : "";
      var node = document.createElement("details");
      node.id = "case-" + c.id;
      node.open = true;
      node.className = c.breaking ? "bad" : "";
      node.innerHTML = "<summary><b>" + esc(c.id) + "</b> (" + esc(c.kind) + ", " + esc(c.dim) + "-D) &mdash; " +
        esc(c.description) + " <i>" + esc(c.tags) + "</i>" + twin + "</summary>" +
        '<p class="mono">' + esc(c.source) + ": " + esc(c.inputs) + "</p>" +
        "<table><thead><tr><th>engine</th><th>quantity</th><th>value</th><th>truth</th><th>error</th>" +
        "<th>tolerance</th><th>status</th><th>category</th><th>reason</th>" +
        "<th>query: median &plusmn; IQR of its samples</th></tr></thead><tbody>" + body + "</tbody></table>";
      document.getElementById("case-details").prepend(node);
      return node;
    }
    function open() {
      var id;
      try { id = decodeURIComponent(location.hash.slice(6)); } catch (e) { return; }
      if (location.hash.slice(0, 6) !== "#case-" || !(id in byId)) { return; }
      var node = document.getElementById("case-" + id) || build(byId[id]);
      node.open = true;
      node.scrollIntoView();
    }
    window.addEventListener("hashchange", open);
    open();
  }

  ready(function () {
    if (!document.getElementById("results-data")) { return; }
    cc.resultsData = cc.unpack("results-data").then(JSON.parse);
    var dataTables = Promise.all([cc.unpack("datatables-js"), cc.unpack("datatables-css")])
      .then(function (parts) {
        var style = document.createElement("style");
        style.textContent = parts[1];
        document.head.insertBefore(style, document.head.querySelector("style"));
        var url = URL.createObjectURL(new Blob([parts[0]], {type: "text/javascript"}));
        return import(url).then(function (module) { URL.revokeObjectURL(url); return module.default; });
      });
    Promise.all([cc.resultsData, dataTables]).then(function (loaded) {
      resultsTable(loaded[0], loaded[1]);
    }).catch(function (e) { console.error(e); });
    if (document.getElementById("case-details")) {
      cc.resultsData.then(caseDetails).catch(function (e) { console.error(e); });
    }
  });

  /* The coverage map (crosscheck/report/coverage.py, coverage_page.py): every cell's label code,
     colour and words are decided in Python; this draws the chosen grid of each space for the
     chosen engine from the packed data. */
  ready(function () {
    var section = document.getElementById("coverage");
    if (!section || !document.getElementById("coverage-data")) { return; }
    var data = null, engine = document.getElementById("coverage-engine");
    function draw(fold) {
      var space = data.spaces[Number(fold.dataset.space)];
      var grid = space.grids[Number(fold.querySelector("select.coverage-pair").value)];
      var e = Number(engine.value), codes = grid.status[e], errors = grid.error[e];
      var n = grid.column_levels.length, html = ['<div class="wide"><table class="coverage-grid"><thead><tr><th>',
        esc(grid.rows), " \u2193 \u00a0 ", esc(grid.columns), " \u2192</th>"];
      grid.column_levels.forEach(function (level) { html.push("<th>", esc(level), "</th>"); });
      html.push("</tr></thead><tbody>");
      grid.row_levels.forEach(function (row, r) {
        html.push("<tr><th>", esc(row), "</th>");
        grid.column_levels.forEach(function (column, k) {
          var i = r * n + k, key = data.keys[codes[i]], cases = grid.cases[i];
          var error = data.errors[data.error_codes.indexOf(errors[i])];
          var title = grid.rows + " " + row + ", " + grid.columns + " " + column + ": " +
            (cases <= 0 ? key.label : cases + (cases === 1 ? " case; " : " cases; ") +
             data.engines[e] + ": " + key.label + (error ? ", largest " + error : ""));
          html.push('<td data-code="', codes[i], '" data-row="', esc(row), '" data-column="', esc(column),
                    '" style="background: ', key.colour, "; color: ", key.ink, '" title="', esc(title), '">',
                    cases > 0 ? cases : "", "</td>");
        });
        html.push("</tr>");
      });
      html.push("</tbody></table></div>");
      fold.querySelector("div.coverage-grid").innerHTML = html.join("");
    }
    function drawAll() { section.querySelectorAll("details.coverage-space").forEach(draw); }
    cc.unpack("coverage-data").then(function (packed) {
      data = JSON.parse(packed);
      data.keys = {};
      data.legend.forEach(function (entry) { data.keys[entry.code] = entry; });
      drawAll();
      section.dataset.ready = "";
      engine.addEventListener("change", drawAll);
      section.querySelectorAll("select.coverage-pair").forEach(function (select) {
        select.addEventListener("change", function () { draw(select.closest("details")); });
      });
    });
  });

  /* The advise form (crosscheck/report/advise/page.py) writes the crosscheck advise command of
     the profile its fields state: each field is one option (data-option), joined in order. */
  ready(function () {
    var form = document.getElementById("advise-form");
    if (!form) { return; }
    var out = document.getElementById("advise-command");
    function write() {
      var words = ["crosscheck", "advise", form.dataset.run];
      form.querySelectorAll("[data-option]").forEach(function (field) {
        var value = field.type === "checkbox" ? field.checked : field.value.trim();
        if (field.type === "checkbox" && value) { words.push(field.dataset.option); }
        else if (field.type !== "checkbox" && value !== "") { words.push(field.dataset.option, value); }
      });
      out.textContent = words.map(shellWord).join(" ");
    }
    form.addEventListener("input", write);
    form.addEventListener("change", write);
    cc.adviseCommand = function () { write(); return out.textContent; };
    write();
  });
})();
