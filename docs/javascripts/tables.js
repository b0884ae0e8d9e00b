// A table wider than the content column even with its text wrapped at spaces gets the
// attribute data-dense="1": tighter cells, smaller type, and code spans that break anywhere
// (extra.css).  If it is still too wide, data-dense="2": every cell breaks inside words too.
// So a table fits the column instead of scrolling sideways.  Re-measured when the window is
// resized and when a collapsed note opens (a table inside a closed note has no width).
(function () {
  function tooWide(wrap) {
    return wrap.scrollWidth > wrap.clientWidth + 1;
  }
  function fit(root) {
    (root || document).querySelectorAll(".md-typeset table").forEach(function (table) {
      var wrap = table.closest(".md-typeset__scrollwrap");
      if (!wrap || table.offsetParent === null) return;
      table.removeAttribute("data-dense");
      ["1", "2"].forEach(function (level) {
        if (tooWide(wrap)) table.setAttribute("data-dense", level);
      });
    });
  }
  function init() {
    fit(document);
    document.querySelectorAll("details").forEach(function (d) {
      d.addEventListener("toggle", function () { if (d.open) fit(d); });
    });
  }
  if (window.document$ && typeof window.document$.subscribe === "function") {
    window.document$.subscribe(init);
  } else if (document.readyState === "loading") {
    document.addEventListener("DOMContentLoaded", init);
  } else {
    init();
  }
  var timer = null;
  window.addEventListener("resize", function () {
    clearTimeout(timer);
    timer = setTimeout(function () { fit(document); }, 100);
  });
})();
