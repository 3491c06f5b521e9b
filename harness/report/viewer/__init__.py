"""The viewer: recorded runs of a scene played side by side in the browser (three.js)."""
