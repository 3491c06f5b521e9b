// Appended to a copy of a report page by tests/browser_checks.py: measures what the browser
// laid out and writes it as JSON into <body data-check=...> for `chromium --dump-dom`.
(function () {
  "use strict";
  function sleep(ms) { return new Promise((resolve) => setTimeout(resolve, ms)); }

  async function viewerFrames(root) {
    for (let i = 0; i < 100 && !root.dataset.ready; i++) await sleep(100);
    if (root.dataset.ready !== "true") return { ready: root.dataset.ready || "no" };
    const viewer = window.clearbenchViewers.find((v) => v.root === root);
    const canvas = root.querySelector("canvas");
    const picture = () => canvas.toDataURL("image/png");
    const start = viewer.frame;            // the frame the page opened at (?view-event=...)
    viewer.show(0);
    const first = picture();
    viewer.show(viewer.times.length - 1);
    const last = picture();
    // the slider moved as a reader moves it (an input event), to the middle frame
    const slider = root.querySelector(".cb-slider");
    slider.value = String(Math.floor((viewer.times.length - 1) / 2));
    slider.dispatchEvent(new Event("input"));
    const middle = { frame: viewer.frame, differ: picture() !== first && picture() !== last };
    // each event's button: the frame it shows and whether its picture is its own
    const events = {};
    const pictures = [];
    for (const button of root.querySelectorAll(".cb-event")) {
      button.click();
      events[button.textContent.trim().split(" ")[0]] = viewer.times[viewer.frame];
      pictures.push(picture());
    }
    return { ready: "true", frames: viewer.times.length, differ: first !== last,
             start: viewer.times[start], middle, events,
             eventsDiffer: new Set(pictures).size === pictures.length,
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
    out.matrixCells = Object.fromEntries([...cells].map(
      (c) => [`${c.dataset.scene}|${c.dataset.engine}`, c.dataset.verdict]));
    out.viewers = [];
    for (const root of document.querySelectorAll(".cb-viewer")) out.viewers.push(await viewerFrames(root));
    body.setAttribute("data-check", JSON.stringify(out));
  }

  window.addEventListener("load", () => { check(); });
})();
