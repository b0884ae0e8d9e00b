// Renders the TeX that pymdownx.arithmatex (generic mode) leaves in the page: \( ... \) in
// span.arithmatex and \[ ... \] in div.arithmatex, with the KaTeX bundled in javascripts/katex/.
// Only those elements are scanned, so a "$" in prose or code stays as it is; a formula KaTeX
// cannot parse shows as a red .katex-error instead of stopping the others.
(function () {
  function render(root) {
    if (typeof renderMathInElement !== "function") { return; }
    root.querySelectorAll(".arithmatex").forEach(function (el) {
      renderMathInElement(el, {
        delimiters: [
          { left: "\\(", right: "\\)", display: false },
          { left: "\\[", right: "\\]", display: true }
        ],
        throwOnError: false
      });
    });
  }
  if (typeof document$ !== "undefined") {
    document$.subscribe(function () { render(document); });
  } else {
    document.addEventListener("DOMContentLoaded", function () { render(document); });
  }
})();
