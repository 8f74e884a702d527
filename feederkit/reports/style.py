"""The report's stylesheet: system fonts only, a laptop-width column, and an A4 print layout."""

CSS = """
:root { --ink: #1d232a; --muted: #66707a; --line: #9aa7b2; --bg: #f6f8fa; --warn: #a33; }
* { box-sizing: border-box; }
body { margin: 0; color: var(--ink); background: #fff;
  font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif; }
main { max-width: 1120px; margin: 0 auto; padding: 1.2rem 1.5rem 3rem; }
h1 { font-size: 1.5rem; margin: .2rem 0 .4rem; }
h2 { font-size: 1.2rem; margin: 1.6rem 0 .5rem; padding-bottom: .2rem;
  border-bottom: 1px solid #dde3e8; }
h3 { font-size: 1.05rem; margin: 1.2rem 0 .4rem; }
.muted { color: var(--muted); font-weight: normal; }
.warn { color: var(--warn); }
.banner { border: 2px solid var(--warn); background: #fbeaea; color: var(--warn);
  padding: 0.5em 0.8em; margin: 0.6em 0; font-weight: bold; }
.banner.caution { border-color: #b7791f; background: #fdf6e3; color: #8a5a00; }
.lead { font-size: 1.05rem; margin: .2rem 0 .8rem; }
.swatch { display: inline-block; width: .9em; height: .9em; border-radius: 2px;
  margin-right: .4em; vertical-align: -0.1em; border: 1px solid #0003; }
ul.mix { list-style: none; padding: 0; margin: .3rem 0; display: flex; flex-wrap: wrap;
  gap: .3rem 1.4rem; }
table { border-collapse: collapse; }
table.kv th { text-align: left; font-weight: 600; padding: .15rem 1.2rem .15rem 0;
  vertical-align: top; }
table.kv td { padding: .15rem 0; }
table.grid th, table.grid td { border: 1px solid #dde3e8; padding: .2rem .5rem; text-align: left;
  vertical-align: middle; }
table.grid th { background: var(--bg); font-weight: 600; }
table.states td svg { display: block; }
ul.tree, ul.tree ul { list-style: none; margin: 0; padding: 0; }
ul.tree ul { padding-left: 1.6rem; }
ul.tree li { position: relative; padding: .35rem 0 0 1.1rem; }
ul.tree > li { padding-left: 0; }
ul.tree ul > li::before { content: ""; position: absolute; left: 0; top: 0; bottom: 0;
  border-left: 2px solid var(--line); }
ul.tree ul > li:last-child::before { bottom: auto; height: 1.3rem; }
ul.tree ul > li::after { content: ""; position: absolute; left: 0; top: 1.3rem; width: .9rem;
  border-top: 2px solid var(--line); }
.edge { display: inline-flex; gap: .6rem; align-items: baseline; font-size: .9rem;
  background: #eef3f7; border: 1px solid #d3dde6; border-radius: 1rem; padding: .05rem .7rem;
  margin: 0 0 .3rem; }
.edge .act { font-weight: 600; }
.tree-node { border: 1px solid #c9d3dc; border-radius: 6px; padding: .35rem .55rem .4rem;
  background: #fff; width: fit-content; max-width: 100%; }
.tree-node.result { background: #eaf6ee; border-color: #8cc59c; }
.tree-node.result.symmetric { background: #eef3fb; border-color: #8fa9d6; }
.tree-node.result.unoriented { background: #fdf0e6; border-color: #d99a5e; }
.tree-node.result.confused { background: #fbeeee; border-color: #d68f8f; }
.tree-node.result.reject { background: #fdf6e3; border-color: #d6b36a; }
.shared-tag { color: #0b5a8a; font-weight: 600; }
.tree-ref { display: inline-block; padding: 3px 8px; border: 1px dashed var(--line);
  border-radius: 6px; color: #0b5a8a; }
.node-head { font-size: .92rem; margin-bottom: .2rem; }
.node-op { font-size: .88rem; color: var(--muted); margin-top: .15rem; }
.poses { display: flex; flex-wrap: wrap; gap: .25rem .5rem; }
figure { margin: 0; }
.poses figure { text-align: center; }
.poses figcaption { font-size: .74rem; line-height: 1.15; max-width: 9rem;
  overflow-wrap: anywhere; }
.pose-deg { color: var(--muted); }
svg.pose .fence { fill: #3b4249; }
.part-grid { display: grid; grid-template-columns: minmax(0, 1fr) minmax(0, 1fr); gap: 1rem;
  align-items: start; }
figure.plot img { width: 100%; height: auto; display: block; border: 1px solid #eef1f4; }
figure.plot figcaption { font-size: .8rem; color: var(--muted); }
#conventions p { max-width: 70rem; }
@media (max-width: 820px) { .part-grid { grid-template-columns: 1fr; } }
@page { size: A4; margin: 12mm; }
@media print {
  body { font-size: 9.5pt; -webkit-print-color-adjust: exact; print-color-adjust: exact; }
  main { max-width: none; padding: 0; }
  h2 { break-after: avoid; }
  .tree-node, .edge, tr, figure { break-inside: avoid; }
  section.part { break-before: page; }
  .part-grid { grid-template-columns: 1fr 1fr; }
  figure.plot img { max-height: 230mm; width: auto; max-width: 100%; }
  a { color: inherit; text-decoration: none; }
}
"""
