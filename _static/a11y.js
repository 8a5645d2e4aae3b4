/* Every frame that scrolls sideways can be reached and scrolled from the keyboard.
   A box of the article whose content is wider than the box (a figure shown at its drawn size, a
   printed matrix, a long table) and that holds nothing focusable of its own becomes a tab stop: a
   named region ("output, scrolls sideways") whose arrow keys scroll it. Boxes that stop
   overflowing (a wider window) lose the tab stop again. Run once the page, its pictures and its
   mathematics are laid out, and again when the window's width changes. */
(function () {
  "use strict";
  var BOXES = "div.cell_output, div.output, pre, .table-wrapper, table, div.math, figure";
  var FOCUSABLE = "a[href], button, input, select, textarea, summary, [tabindex]";
  var MARK = "data-uio-scroll";

  function label(el) {
    if (el.closest("div.cell_output")) return "output, scrolls sideways";
    if (el.matches("pre")) return "code, scrolls sideways";
    if (el.matches("div.math")) return "equation, scrolls sideways";
    if (el.matches("table, .table-wrapper")) return "table, scrolls sideways";
    return "scrolls sideways";
  }

  function mark() {
    var main = document.querySelector("main") || document.body;
    main.querySelectorAll(BOXES).forEach(function (el) {
      var ours = el.hasAttribute(MARK);
      var style = getComputedStyle(el);
      var scrolls = (style.overflowX === "auto" || style.overflowX === "scroll") &&
        el.scrollWidth > el.clientWidth + 1;
      if (scrolls && !ours && !el.hasAttribute("tabindex") && !el.querySelector(FOCUSABLE)) {
        el.setAttribute(MARK, "");
        el.setAttribute("tabindex", "0");
        if (!el.hasAttribute("role")) {
          el.setAttribute("role", "region");
          el.setAttribute(MARK, "role");
        }
        if (!el.hasAttribute("aria-label")) el.setAttribute("aria-label", label(el));
      } else if (!scrolls && ours) {
        if (el.getAttribute(MARK) === "role") el.removeAttribute("role");
        el.removeAttribute("tabindex");
        el.removeAttribute("aria-label");
        el.removeAttribute(MARK);
      }
    });
  }

  var pending = null;
  function later() {
    if (pending) cancelAnimationFrame(pending);
    pending = requestAnimationFrame(function () { pending = null; mark(); });
  }

  window.addEventListener("load", function () {
    mark();
    if (window.MathJax && window.MathJax.startup && window.MathJax.startup.promise) {
      window.MathJax.startup.promise.then(mark);
    }
    if (window.ResizeObserver) {
      new ResizeObserver(later).observe(document.querySelector("main") || document.body);
    } else {
      window.addEventListener("resize", later);
    }
  });
  document.addEventListener("toggle", later, true); /* a <details> opened or closed */
})();
