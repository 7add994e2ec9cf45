/* The book's own behaviour in the browser (book/_ext/bmc_book.py adds this file to every
 * page, after MathJax's configuration):
 *
 * 1. Display equations fit the text column. MathJax 3 does not break a long formula, so
 *    one wider than the column would be cut off at the column's edge (at 400 px most of
 *    the display equations of a page). A wider one is scaled down to the column, but not
 *    below MIN_SCALE (70 %) of its size (smaller, its subscripts could not be read): what is
 *    still wider scrolls sideways inside its own box, the page itself never does.
 * 2. Search results typeset their mathematics: a notebook title with maths ("when
 *    $\det(UV^T) = -1$") is a result's title, added to the page after MathJax has run.
 * 3. A figure shown smaller than it was drawn (a notebook's 12-inch figure in a column of
 *    800 px, any figure on a phone) opens at its full size when clicked: it is wrapped in
 *    a link to its image file.
 */
(function () {
  "use strict";
  const MIN_SCALE = 0.7;

  function fitEquation(box) {
    const svg = box.querySelector(":scope > svg");
    if (!svg) return;
    if (svg.dataset.bmcWidth === undefined) {
      // the size MathJax gave it (in ex), kept to scale from on every resize
      svg.dataset.bmcWidth = svg.getAttribute("width") || "";
      svg.dataset.bmcHeight = svg.getAttribute("height") || "";
    }
    svg.setAttribute("width", svg.dataset.bmcWidth);
    svg.setAttribute("height", svg.dataset.bmcHeight);
    box.classList.remove("bmc-scaled", "bmc-scrolls");
    const available = box.clientWidth;
    const natural = svg.getBoundingClientRect().width;
    if (!available || natural <= available + 0.5) return;
    const scale = Math.max(MIN_SCALE, available / natural);
    const height = svg.getBoundingClientRect().height;
    svg.setAttribute("width", `${natural * scale}px`);
    svg.setAttribute("height", `${height * scale}px`);
    box.classList.add(scale > MIN_SCALE ? "bmc-scaled" : "bmc-scrolls");
  }

  function fitEquations() {
    document.querySelectorAll('mjx-container[jax="SVG"][display="true"]').forEach(fitEquation);
    document.body.dataset.bmcEquationsFitted = "true";
  }

  function typesetSearchResults() {
    const results = document.getElementById("search-results");
    if (!results) return;
    let pending = null;
    new MutationObserver(() => {
      if (pending) return;
      pending = setTimeout(() => {
        pending = null;
        if (!results.textContent.includes("\\(")) return;   // nothing (left) to typeset
        MathJax.typesetPromise([results]);
      }, 50);
    }).observe(results, { childList: true, subtree: true });
  }

  function linkShrunkFigures() {
    document.querySelectorAll("article img").forEach((img) => {
      const mark = () => {
        if (img.closest("a") || !img.naturalWidth) return;
        if (img.getBoundingClientRect().width >= 0.9 * img.naturalWidth) return;
        const link = document.createElement("a");
        link.href = img.src;
        link.className = "bmc-full-size";
        link.title = "Open the figure at its full size";
        img.replaceWith(link);
        link.appendChild(img);
      };
      if (img.complete) mark(); else img.addEventListener("load", mark);
    });
  }

  function whenMathJaxIsReady(action) {
    const start = Date.now();
    (function wait() {
      if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
        MathJax.startup.promise.then(action);
      } else if (Date.now() - start < 30000) {
        setTimeout(wait, 50);
      }
    })();
  }

  document.addEventListener("DOMContentLoaded", () => {
    linkShrunkFigures();
    whenMathJaxIsReady(() => {
      fitEquations();
      typesetSearchResults();
    });
    let resizing = null;
    window.addEventListener("resize", () => {
      clearTimeout(resizing);
      resizing = setTimeout(() => {
        fitEquations();
        linkShrunkFigures();
      }, 100);
    });
  });
})();
