"""The report as one self-contained HTML document: the summary (engine, files with provenance
and SHA-256, verdict, top gaps), a section per step with its tables and figures, and the
commands and versions that reproduce it. Nothing is fetched (data-URI figures, inline style,
a content security policy forbidding every other source), no script runs; the print rules of
:data:`powertrain.results.html.STYLE` give A4 pages.
"""

from __future__ import annotations

from powertrain.reporting.steps import STEPS, shown
from powertrain.results.html import STYLE, esc, figure_html, number, paragraph, synthetic_mark, table

#: Sources the document may use: inline style, images from data URIs; nothing else.
CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'"


def document(title: str, body: str) -> str:
    """The complete HTML file around ``body`` (a ``.pt-report`` block)."""
    return ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            f'<meta http-equiv="Content-Security-Policy" content="{CSP}">\n'
            '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
            '<link rel="icon" href="data:,">\n'
            f"<title>{esc(title)}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n"
            f"{body}\n</body>\n</html>\n")


def body(rep, provenance) -> str:
    """The content of report ``rep``: header, summary, the steps' sections (figures with
    ``provenance`` at their foot), reproduction."""
    parts = [f"<h1>{esc(rep.study.title)}</h1>",
             paragraph(f"Correlation report of study {shown(rep.study.path)}; powertrain "
                       f"{rep.versions.get('powertrain', '')}, {rep.created}.", "meta"),
             _summary(rep)]
    parts += [_section(name, rep.parts[name], provenance) for name in STEPS
              if name in rep.parts]
    parts.append(_reproduce(rep))
    return f'<main class="pt-report">{"".join(parts)}</main>'


def _summary(rep) -> str:
    study = rep.study
    engine = study.engine
    measured = [f"<code>{esc(shown(m.source))}</code>{synthetic_mark(m.synthetic)}"
                + (f" ({esc(label)})" if label else "")
                for label, m, _, _ in study.runs()]
    steps = ", ".join(STEPS[name].title.split(":")[0].lower() for name in rep.parts)
    out = ["<section id=\"summary\"><h2>Summary</h2>",
           f"<p>Engine: {esc(engine.name)} (<code>{esc(shown(engine.file))}</code>)<br>"
           f"Measured: {'; '.join(measured) if measured else 'none'}<br>"
           f"Steps: {esc(steps)}</p>",
           paragraph(rep.verdict(), "verdict")]
    gaps = rep.top_gaps()
    if gaps:
        runs = len(rep.parts.get("compare", [])) > 1
        rows = [([g["run"]] if runs else []) + [
            g["mount"], g["direction"], g["quantity"], number(g["rms_db"]),
            number(g["bias_db"], "+.2f"), number(g["max_abs_db"]),
            number(g.get("rpm_at_max_abs_db"), "g")] for g in gaps]
        out.append(table((["run"] if runs else []) + [
            "mount", "dir", "quantity", "RMS gap [dB]", "bias [dB]", "max |gap| [dB]",
            "at [rpm]"], rows, f"Top gaps: the {len(rows)} channel-quantities with the "
            f"largest RMS gap 20 log10(sim/measured) ({gaps[0]['from']})"))
    out.append(_files(rep.files))
    return "".join(out) + "</section>"


def _files(files) -> str:
    rows = "".join(
        f"<tr><td>{esc(f.role)}</td><td><code>{esc(shown(f.path))}</code>"
        f'{synthetic_mark(f.synthetic)}<br><span class="hash">{esc(f.sha256)}</span></td>'
        f'<td>{esc(f.provenance)}</td><td class="num">{f.size:,}</td></tr>'
        for f in files)
    return ("<table><caption>Files read: path and SHA-256, what each is (its first comment "
            "lines), size in bytes</caption><thead><tr><th>role</th><th>file, SHA-256</th>"
            "<th>provenance</th><th>bytes</th></tr></thead>"
            f"<tbody>{rows}</tbody></table>")


def _section(name: str, parts: list, provenance) -> str:
    step = STEPS[name]
    out = [f'<section class="step" id="{esc(name)}"><h2>{esc(step.title)}</h2>']
    for label, result in parts:
        if label:
            out.append(f"<h3>{esc(label)}</h3>")
        out.append(step.html(result))
        out += [figure_html(draw(), caption) for caption, draw in
                step.figures(result, provenance)]
    return "".join(out) + "</section>"


def _reproduce(rep) -> str:
    study = rep.study
    lines = [rep.command(), f"# or in Python: import powertrain as pt; "
             f"pt.report({shown(study.path)!r}, out={rep.out_name()!r})",
             "# each step alone (the same numbers):"]
    for name, opts in study.steps.items():
        lines += STEPS[name].commands(study, opts)
    versions = [[k, v] for k, v in rep.versions.items()]
    return ('<section id="reproduce"><h2>Reproduce</h2>'
            + paragraph("Run in the folder the report was made in (paths relative to it), "
                        "with the files of the summary (same SHA-256):")
            + f"<pre>{esc(chr(10).join(lines))}</pre>"
            + table(["package", "version"], versions,
                    f"Versions; made {rep.created}, the steps ran in {rep.seconds:.1f} s")
            + "</section>")
