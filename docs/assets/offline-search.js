/* Search for the site opened from disk (file://).
 *
 * The theme's search runs in a web worker that loads search/search_index.json; browsers
 * refuse both from file:// pages. There this script loads the same index as a script
 * (search/search_index.js, written by docs/_build/hooks.py after the build) and answers
 * the search box itself: every query term must occur in a section's title or text;
 * sections are ranked by title hits, then by the number of occurrences. Served over
 * http(s), it does nothing and the theme's search works as usual.
 */
(function () {
  "use strict";
  if (window.location.protocol !== "file:") return;

  function base() {
    var cfg = document.getElementById("__config");
    try { return JSON.parse(cfg.textContent).base || "."; } catch (e) { return "."; }
  }

  function plain(html) {
    var div = document.createElement("div");
    div.innerHTML = html;
    return div.textContent || "";
  }

  function rank(docs, query) {
    var terms = query.toLowerCase().split(/\s+/).filter(function (t) { return t.length; });
    if (!terms.length) return [];
    var hits = [];
    docs.forEach(function (doc) {
      var title = doc.title.toLowerCase(), text = doc.plain.toLowerCase(), score = 0;
      for (var i = 0; i < terms.length; i++) {
        var inTitle = title.indexOf(terms[i]) >= 0, count = text.split(terms[i]).length - 1;
        if (!inTitle && !count) return;
        score += (inTitle ? 100 : 0) + Math.min(count, 20);
      }
      hits.push({ doc: doc, score: score, term: terms[0] });
    });
    hits.sort(function (a, b) { return b.score - a.score; });
    return hits.slice(0, 30);
  }

  function snippet(text, term) {
    var at = text.toLowerCase().indexOf(term), start = Math.max(0, at - 60);
    return (start ? "…" : "") + text.slice(start, start + 200) + (text.length > start + 200 ? "…" : "");
  }

  function render(hits, query, root) {
    var meta = document.querySelector(".md-search-result__meta");
    var list = document.querySelector(".md-search-result__list");
    if (!list) return;
    list.textContent = "";
    if (meta) {
      meta.textContent = !query.trim() ? "Type to start searching"
        : hits.length ? hits.length + " matching sections" : "No matching sections";
    }
    hits.forEach(function (hit) {
      var item = document.createElement("li"), link = document.createElement("a");
      var article = document.createElement("article"), h = document.createElement("h1");
      var p = document.createElement("p");
      item.className = "md-search-result__item";
      link.className = "md-search-result__link";
      link.href = root + "/" + hit.doc.location;
      article.className = "md-search-result__article md-typeset";
      h.textContent = hit.doc.title;  // text, never markup: titles come from user pages
      p.textContent = snippet(hit.doc.plain, hit.term);
      article.appendChild(h);
      article.appendChild(p);
      link.appendChild(article);
      item.appendChild(link);
      list.appendChild(item);
    });
  }

  function start() {
    var input = document.querySelector("[data-md-component=search-query]");
    var box = document.querySelector("[data-md-component=search]");
    if (!input || !box) return;
    box.removeAttribute("hidden");  // the theme shows it once its worker is ready
    var root = base(), docs = null;
    var script = document.createElement("script");
    script.src = root + "/search/search_index.js";
    script.onload = function () {
      docs = (window.__serialkinSearchIndex || { docs: [] }).docs.map(function (d) {
        return { location: d.location, title: plain(d.title), plain: plain(d.text) };
      });
      if (input.value) render(rank(docs, input.value), input.value, root);
    };
    document.head.appendChild(script);
    input.removeAttribute("disabled");
    var answer = function (event) {
      event.stopImmediatePropagation();
      if (docs) render(rank(docs, input.value), input.value, root);
    };
    input.addEventListener("input", answer, true);
    input.addEventListener("focus", function () {  // open the results panel, as the theme does
      var toggle = document.getElementById("__search");
      if (toggle) toggle.checked = true;
    });
    input.addEventListener("keyup", function () { if (docs) render(rank(docs, input.value), input.value, root); });
  }

  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start);
  else start();
})();
