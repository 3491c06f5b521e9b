// Appended to a copy of a report page by tests/browser_page.py: measures what the browser
// laid out and writes it as JSON into <body data-check=...> for `chromium --dump-dom`.
(function () {
  "use strict";
  function sleep(ms) { return new Promise((resolve) => setTimeout(resolve, ms)); }

  async function viewerFrames(root) {
    for (let i = 0; i < 100 && !root.dataset.ready; i++) await sleep(100);
    if (root.dataset.ready !== "true") return { ready: root.dataset.ready || "no" };
    const viewer = window.clearbenchViewers.find((v) => v.root === root);
    const canvas = root.querySelector("canvas");
    viewer.show(0);
    const first = canvas.toDataURL("image/png");
    viewer.show(viewer.times.length - 1);
    const last = canvas.toDataURL("image/png");
    return { ready: "true", frames: viewer.times.length, differ: first !== last,
             width: canvas.getBoundingClientRect().width };
  }

  async function check() {
    const out = {};
    const body = document.body;
    const column = body.getBoundingClientRect();
    const style = getComputedStyle(body);
    const right = column.right - parseFloat(style.paddingRight) + 1;
    out.column = column.width - parseFloat(style.paddingLeft) - parseFloat(style.paddingRight);
    const matrix = document.getElementById("overview-matrix");
    out.matrix = matrix ? matrix.getBoundingClientRect().width : null;
    const cells = document.querySelectorAll("#overview-matrix td.verdict");
    out.cells = cells.length;
    out.notRun = [...cells].filter((c) => c.dataset.verdict === "not run").length;
    out.pageScroll = document.documentElement.scrollWidth - document.documentElement.clientWidth;
    out.wide = [...document.querySelectorAll("p,li,pre,table,figure,img,h1,h2,h3,dl,nav,ul")]
      .filter((e) => !e.closest(".scroll") && e.getBoundingClientRect().right > right)
      .map((e) => `${e.tagName} ${e.id || e.className} ${e.textContent.slice(0, 60)}`);
    out.scrolling = [...document.querySelectorAll(".scroll")]
      .filter((e) => e.scrollWidth > e.clientWidth + 1)
      .map((e) => (e.querySelector("caption") || e).textContent.slice(0, 60));
    out.broken = [...document.querySelectorAll("a[href^='#']")]
      .map((a) => a.getAttribute("href"))
      .filter((h) => !document.getElementById(decodeURIComponent(h.slice(1))));
    out.tocLinks = document.querySelectorAll("#toc a").length;
    out.viewers = [];
    for (const root of document.querySelectorAll(".cb-viewer")) out.viewers.push(await viewerFrames(root));
    body.setAttribute("data-check", JSON.stringify(out));
  }

  window.addEventListener("load", () => { check(); });
})();
