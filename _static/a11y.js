/* The keyboard's and the screen reader's way through a page of the book.

   * Formulas are not Tab stops (MathJax's menu setting inTabOrder is off in _config.yml): Tab
     reaches the links and controls only. The key M moves the focus to the next formula and
     Shift+M to the one before (Space or the context-menu key there opens MathJax's menu); a
     note at the top of the article says so to a screen reader.
   * Every frame that scrolls sideways can be reached and scrolled from the keyboard. A box of
     the article whose content is wider than the box (a figure shown at its drawn size, a printed
     matrix, a long table, a display equation) and that holds nothing focusable of its own
     becomes a tab stop: a group (not a landmark) named by what it holds ("output of code cell 4,
     scrolls sideways", "code cell 4, 12 lines, scrolls sideways", "table: ...") whose arrow keys
     scroll it. The side where content is cut off carries a visible bar (data-uio-cut, a11y.css)
     while there is more to scroll to there. Boxes that stop overflowing lose all of it again.
   * Code cells are announced as code with their number of lines (a group whose role
     description is "code"), their copy buttons by the cell they copy ("copy code cell 4", not
     forty times "Copy to clipboard"), the hidden-code toggles by the words they show ("Show
     code cell source", not "Toggle hidden content").
   Run once the page, its pictures and its mathematics are laid out, and again when the window's
   width changes. */
(function () {
  "use strict";
  var BOXES = "div.cell_output, div.output, pre, .table-wrapper, table, div.math, figure, " +
    "mjx-container[display='true']";
  var FOCUSABLE = "a[href], button, input, select, textarea, summary, " +
    "[tabindex]:not([tabindex='-1'])";
  var MARK = "data-uio-scroll";
  var CUT = "data-uio-cut";
  var NAMED = "data-uio-name";  /* the name a frame was given, before two alike were told apart */

  function words(el, most) {
    var text = (el.textContent || "").replace(/\s+/g, " ").trim();
    return text.length > most ? text.slice(0, most).replace(/\s\S*$/, "") + " …" : text;
  }

  function lines(pre) {
    var text = (pre.textContent || "").replace(/\n+$/, "");
    return text ? text.split("\n").length : 0;
  }

  function cellNumber(el) {
    var cell = el.closest("div.cell");
    if (!cell) return 0;
    return Array.prototype.indexOf.call(document.querySelectorAll("main div.cell"), cell) + 1;
  }

  function count(n, one) {
    return n + " " + one + (n === 1 ? "" : "s");
  }

  function label(el) {
    var n = cellNumber(el);
    if (el.matches("mjx-container")) {
      var box = el.closest("div.math");
      var number = box && box.querySelector(".eqno");
      return "equation" + (number ? " " + words(number, 20).replace("#", "").trim() : "") +
        ", scrolls sideways";
    }
    if (el.closest("div.cell_output")) {
      if (el.querySelector("img")) {
        var alt = el.querySelector("img").getAttribute("alt") || "";
        return "figure" + (n ? " of code cell " + n : "") +
          (alt ? ": " + alt.split(". ")[0] : "") + ", scrolls sideways";
      }
      if (el.matches("table, .table-wrapper") || el.querySelector("table")) {
        return "table" + (n ? " printed by code cell " + n : "") + ", scrolls sideways";
      }
      return "output of code cell " + n + (el.matches("pre") ? ", " + count(lines(el), "line") : "") +
        ", scrolls sideways";
    }
    if (el.matches("pre")) {
      if (n) return "code cell " + n + ", " + count(lines(el), "line") + ", scrolls sideways";
      /* a block of code outside the cells (an example of the API page): its place and whose */
      var k = Array.prototype.indexOf.call(document.querySelectorAll("main pre"), el) + 1;
      var dd = el.closest("dl.py > dd");
      var dt = dd && dd.previousElementSibling;
      var whose = dt && dt.id ? " of " + dt.id.split(".").pop() : "";
      return "code block " + k + whose + ", " + count(lines(el), "line") + ", scrolls sideways";
    }
    if (el.matches("div.math")) return "equation, scrolls sideways";
    if (el.matches("table, .table-wrapper")) {
      var table = el.matches("table") ? el : el.querySelector("table");
      var caption = table && table.querySelector("caption");
      var head = table && table.querySelector("tr");
      return "table: " + words(caption || head || el, 60) + ", scrolls sideways";
    }
    if (el.matches("figure")) {
      var img = el.querySelector("img");
      return "figure" + (img && img.alt ? ": " + img.alt.split(". ")[0] : "") +
        ", scrolls sideways";
    }
    return "scrolls sideways";
  }

  /* which side of a scrolling frame hides content: "left", "right", "left right" or nothing */
  function cut(el) {
    var sides = [];
    if (el.scrollLeft > 1) sides.push("left");
    if (el.scrollLeft + el.clientWidth < el.scrollWidth - 1) sides.push("right");
    if (sides.length) el.setAttribute(CUT, sides.join(" "));
    else el.removeAttribute(CUT);
  }

  function onScroll(event) {
    cut(event.currentTarget);
  }

  function mark() {
    var main = document.querySelector("main") || document.body;
    main.querySelectorAll(BOXES).forEach(function (el) {
      var ours = el.hasAttribute(MARK);
      var style = getComputedStyle(el);
      var scrolls = (style.overflowX === "auto" || style.overflowX === "scroll") &&
        el.scrollWidth > el.clientWidth;  /* as axe-core counts it: one pixel scrolls */
      var math = el.matches("mjx-container");
      var free = math ? !el.querySelector(FOCUSABLE)
        : !el.hasAttribute("tabindex") && !el.querySelector(FOCUSABLE);
      if (scrolls && !ours && free) {
        el.setAttribute(MARK, math ? "math" : "");
        el.setAttribute("tabindex", "0");
        if (!math && !el.hasAttribute("role")) {
          el.setAttribute("role", "group");
          el.setAttribute(MARK, "role");
        }
        if (!math && !el.hasAttribute("aria-label")) {
          el.setAttribute(NAMED, label(el));
          el.setAttribute("aria-label", el.getAttribute(NAMED));
        }
        el.addEventListener("scroll", onScroll, {passive: true});
        cut(el);
      } else if (!scrolls && ours) {
        var kind = el.getAttribute(MARK);
        if (kind === "role") el.removeAttribute("role");
        if (kind === "math") {
          el.setAttribute("tabindex", "-1");
        } else {
          el.removeAttribute("tabindex");
          if (el.hasAttribute(NAMED)) el.removeAttribute("aria-label");
        }
        el.removeAttribute(NAMED);
        el.removeAttribute(MARK);
        el.removeAttribute(CUT);
        el.removeEventListener("scroll", onScroll);
      } else if (ours) {
        cut(el);
      }
    });
    apart(main);
  }

  /* no two frames under one name: frames named alike (two printed blocks of one cell) are
     told apart as parts, "output of code cell 6, part 2 of 3, 1 line, scrolls sideways" */
  function apart(main) {
    var alike = {};
    main.querySelectorAll("[" + NAMED + "]").forEach(function (el) {
      var name = el.getAttribute(NAMED);
      (alike[name] = alike[name] || []).push(el);
    });
    Object.keys(alike).forEach(function (name) {
      var group = alike[name];
      group.forEach(function (el, i) {
        if (group.length === 1) {
          el.setAttribute("aria-label", name);
          return;
        }
        var part = "part " + (i + 1) + " of " + group.length;
        var head = name.replace(/, scrolls sideways$/, "");
        var at = head.search(/, \d+ lines?$/);
        head = at < 0 ? head + ", " + part : head.slice(0, at) + ", " + part + head.slice(at);
        el.setAttribute("aria-label", head + ", scrolls sideways");
      });
    });
  }

  /* code cells: a group announced as code, with its number of lines */
  function codeCells() {
    document.querySelectorAll("main div.cell div.cell_input").forEach(function (input) {
      var pre = input.querySelector("pre");
      if (!pre || input.hasAttribute("aria-roledescription")) return;
      input.setAttribute("role", "group");
      input.setAttribute("aria-roledescription", "code");
      input.setAttribute("aria-label", "code cell " + cellNumber(input) + ", " +
        count(lines(pre), "line"));
      var copy = input.querySelector("button.copybtn");
      if (copy) copy.setAttribute("aria-label", "copy code cell " + cellNumber(input));
    });
  }

  /* a toggle's name is what it shows: the visible words, not "Toggle hidden content" */
  function toggles() {
    document.querySelectorAll("[aria-label='Toggle hidden content']").forEach(function (el) {
      if ((el.innerText || "").trim()) el.removeAttribute("aria-label");
    });
  }

  /* the formulas: out of the Tab order, reached with M and Shift+M */
  var NOTE = "uio-keyboard-note";

  function formulas() {
    return Array.prototype.slice.call(
      document.querySelectorAll("main mjx-container[jax]")
    ).filter(function (c) { return c.getClientRects().length > 0; });
  }

  function note() {
    var article = document.querySelector("main article, main");
    if (!article || document.getElementById(NOTE) || !formulas().length) return;
    var p = document.createElement("p");
    p.id = NOTE;
    p.className = "uio-sr-only";
    p.textContent = "Keyboard: the formulas are not Tab stops. Press M to move to the next " +
      "formula, Shift+M to the one before; Space there opens the formula's menu.";
    article.insertBefore(p, article.firstChild);
  }

  function typing(target) {
    return target && target.closest &&
      target.closest("input, textarea, select, [contenteditable=''], [contenteditable='true']");
  }

  document.addEventListener("keydown", function (event) {
    if (event.key !== "m" && event.key !== "M") return;
    if (event.ctrlKey || event.altKey || event.metaKey || typing(event.target)) return;
    var all = formulas();
    if (!all.length) return;
    var here = document.activeElement;
    var back = event.shiftKey;
    var next = null;
    if (here && here !== document.body) {
      var order = back ? all.slice().reverse() : all;
      for (var i = 0; i < order.length; i++) {
        var pos = here.compareDocumentPosition(order[i]);
        if (pos & Node.DOCUMENT_POSITION_CONTAINS) continue;  /* the formula focused now */
        if (pos & (back ? Node.DOCUMENT_POSITION_PRECEDING : Node.DOCUMENT_POSITION_FOLLOWING)) {
          next = order[i];
          break;
        }
      }
    } else {  /* nothing focused: the first formula on the screen (or above it, going back) */
      for (var j = 0; j < all.length; j++) {
        var k = back ? all.length - 1 - j : j;
        var top = all[k].getBoundingClientRect().top;
        if (back ? top < 0 : top >= 0) { next = all[k]; break; }
      }
    }
    if (!next) return;
    if (!next.hasAttribute("tabindex")) next.setAttribute("tabindex", "-1");
    event.preventDefault();
    next.focus();
    next.scrollIntoView({block: "nearest", inline: "nearest"});
  });

  var pending = null;
  function later() {
    if (pending) cancelAnimationFrame(pending);
    pending = requestAnimationFrame(function () { pending = null; mark(); });
  }

  function all() {
    mark();
    codeCells();
    toggles();
    note();
  }

  window.addEventListener("load", function () {
    all();
    if (window.MathJax && window.MathJax.startup && window.MathJax.startup.promise) {
      window.MathJax.startup.promise.then(all);
    }
    if (window.ResizeObserver) {
      new ResizeObserver(later).observe(document.querySelector("main") || document.body);
    } else {
      window.addEventListener("resize", later);
    }
  });
  document.addEventListener("toggle", later, true); /* a <details> opened or closed */
  /* a dropdown or hidden cell opened (its "open", class or style changed): its frames are
     checked before anything else runs, not at the next animation frame, so that a frame that
     scrolls is never left out of the keyboard's reach while it shows */
  if (window.MutationObserver) {
    var queued = false;
    new MutationObserver(function () {
      if (queued) return;
      queued = true;
      Promise.resolve().then(function () { queued = false; mark(); });
    }).observe(document.documentElement, {
      attributes: true, subtree: true, attributeFilter: ["open", "class", "style", "hidden"]
    });
  }
})();
