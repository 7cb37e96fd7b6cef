"""``powertrain report``: a study's steps run and written as one self-contained HTML file."""

from __future__ import annotations

import click

from powertrain.cli.common import quiet_option, use_agg
from powertrain.cli.group import main
from powertrain.progress import activity
from powertrain.reporting.report import report as run_report


@main.command()
@click.argument("study", type=click.Path(dir_okay=False))
@click.option("--out", required=True, type=click.Path(dir_okay=False),
              help="HTML file written: one self-contained file (figures embedded, no "
                   "network, no script), printable to A4 PDF.")
@quiet_option
def report(study, out, quiet):
    """Run the steps of a study file and write its report as one HTML file.

    STUDY: a study file (TOML) naming the engine, the measured run-up (measured = FILE) or
    a test plan (plan = PLAN.toml), and the steps to include as tables: [compare],
    [diagnose], [whatif], [modes], [transient]. Paths in it are relative to it. The report:
    a summary (engine, files with provenance and SHA-256, verdict, top gaps), a section per
    step with its tables (per channel, worst first) and figures, and the commands and
    versions that reproduce it.

    \b
    Examples:
      powertrain examples .
      powertrain report examples/study.toml --out report.html
    """
    use_agg()
    with activity("report (running the study's steps)", enabled=not quiet):
        res = run_report(study, out)
    if not quiet:
        click.echo(res.to_text())
        size = len(res.to_html().encode("utf-8"))
        click.echo(f"wrote {out} ({size / 1e6:.1f} MB)")
