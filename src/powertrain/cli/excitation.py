"""``powertrain excitation``: what drives the powertrain at one engine speed."""

from __future__ import annotations

import click

from powertrain.cli import main

#: Leading CSV columns: total load on the powertrain about its CG, engine axes.
LOAD_COLUMNS = ["crank_angle_deg", "fx_n", "fy_n", "fz_n", "mx_nm", "my_nm", "mz_nm"]


@main.command()
@click.option("--rpm", type=float, required=True, help="Engine speed [rpm].")
@click.option("--engine", "engine_file", default=None,
              help="Engine file (TOML) [default: the shipped engines/default.toml].")
@click.option("--load", "load", type=float, default=1.0, show_default=True,
              help="Fraction of the full-load torque [-] (single-zone model).")
@click.option("--no-balancers", is_flag=True, help="Switch the balancer shafts off.")
@click.option("--step", type=float, default=0.5, show_default=True,
              help="Crank-angle step [deg]; must divide 720.")
@click.option("--csv", "csv_path", default=None,
              help="Write one row per crank angle: total load, then per-cylinder columns.")
@click.option("--plot", default=None, help="Write a summary figure (PNG).")
def excitation(rpm, engine_file, load, no_balancers, step, csv_path, plot):
    """Cylinder pressures, gas and inertia forces, crank torque and the total load on the
    powertrain over one engine cycle at --rpm, with the load's order spectrum (0.5..8).

    The load is [Fx, Fy, Fz, Mx, My, Mz] on the powertrain about its centre of gravity in
    engine axes (origin at the 3rd main bearing, X rearwards along the crank, Y right, Z up),
    against the crank angle of cylinder 1 (0..720 deg, 0 = firing TDC of cylinder 1).

    \b
    CSV columns (first seven fixed):
      crank_angle_deg, fx_n, fy_n, fz_n, mx_nm, my_nm, mz_nm,
      then per cylinder i: p{i}_bar, gas_force{i}_n, inertia_force{i}_n, torque{i}_nm
      (gas force on the piston, reciprocating inertia force along the cylinder axis,
      crank torque of that cylinder).

    \b
    Examples:
      powertrain excitation --rpm 3000
      powertrain excitation --rpm 3000 --csv out/load-3000.csv --plot out/load-3000.png
      powertrain excitation --rpm 2000 --engine engines/default.toml --no-balancers
    """
    import math

    from powertrain.errors import InputError
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine

    if not math.isfinite(rpm) or rpm <= 0:
        raise InputError(f"must be a positive speed, got {rpm}", key="--rpm")
    if not math.isfinite(load) or load <= 0:
        raise InputError(f"must be positive, got {load}", key="--load")
    n = 720.0 / step if step > 0 else float("nan")
    if not math.isfinite(n) or abs(n - round(n)) > 1e-9 or round(n) < 32:
        raise InputError(f"must divide 720 deg into at least 32 steps, got {step}",
                         key="--step")
    engine = read_engine(engine_file or DEFAULT_ENGINE_PATH)
    if no_balancers:
        engine = engine.with_balancers(enabled=False)
    try:
        exc = engine.excitation(rpm, n_points=int(round(n)), load=load)
    except ValueError as err:
        if isinstance(err, InputError):
            raise
        raise InputError(str(err), file=engine.file, key="combustion") from None

    if csv_path:
        _write_csv(exc, csv_path)
    if plot:
        from powertrain.cli.common import cli_provenance, engine_description, write_plot
        prov = cli_provenance(engine_description(engine, engine.file,
                                                 no_balancers=no_balancers))
        write_plot(lambda p: exc.plot(path=p, provenance=prov), plot)
    click.echo(summary(engine, exc))


def _write_csv(exc, path):
    import numpy as np

    from powertrain.outputs import atomic_write

    n_cyl = exc.pressure.shape[1]
    header = list(LOAD_COLUMNS)
    cols = [np.degrees(exc.crank_angle)] + [exc.load[:, j] for j in range(6)]
    for i in range(n_cyl):
        header += [f"p{i + 1}_bar", f"gas_force{i + 1}_n", f"inertia_force{i + 1}_n",
                   f"torque{i + 1}_nm"]
        cols += [exc.pressure[:, i] / 1e5, exc.gas_force[:, i], exc.inertia_force[:, i],
                 exc.torque[:, i]]
    data = np.column_stack(cols)
    with atomic_write(path) as fh:
        fh.write(",".join(header) + "\n")
        for row in data:
            fh.write(",".join(f"{v:.9g}" for v in row) + "\n")


def summary(engine, exc) -> str:
    """Short text summary: per-cylinder peak pressure and IMEP, mean torque, load orders."""
    import numpy as np

    from powertrain.cli.common import format_table

    lines = [f"engine: {engine.name}",
             f"speed {exc.rpm:g} rpm, balancer shafts "
             f"{'on' if engine.balancer.enabled else 'off'}"]
    info = exc.info
    if np.isfinite(info.get("p_intake", np.nan)):
        lines.append(f"intake pressure {info['p_intake'] / 1e5:.3f} bar, exhaust "
                     f"{info['p_exhaust'] / 1e5:.3f} bar")
    rows = []
    for i in range(exc.pressure.shape[1]):
        k = int(np.argmax(exc.pressure[:, i]))
        local = np.degrees(engine.local_angles(exc.crank_angle[k])[0, i])
        rows.append([i + 1, float(exc.pressure[k, i] / 1e5), float(local),
                     float(exc.imep[i] / 1e5), float(exc.torque[:, i].mean())])
    lines += ["", format_table(["cyl", "p_max [bar]", "at [deg aTDC]", "IMEP [bar]",
                                "mean torque [N*m]"], rows, "{:.2f}")]
    total = exc.torque.sum(axis=1).mean()
    lines.append(f"mean crank torque {total:.1f} N*m "
                 f"(= IMEP*V_d/(4*pi) = {exc.imep.mean() * engine.crank.displacement / (4 * np.pi):.1f}"
                 " N*m, indicated)")
    orders, amp = exc.order_spectrum(8.0)
    rows = [[f"{o:g}"] + [float(abs(a)) for a in amp[j]] for j, o in enumerate(orders)]
    rows[0] = ["mean"] + [float(a.real) for a in amp[0]]
    lines += ["", "load on the powertrain about its CG, engine axes: mean and order amplitudes",
              format_table(["order", "Fx [N]", "Fy [N]", "Fz [N]", "Mx [N*m]", "My [N*m]",
                            "Mz [N*m]"], rows, "{:.1f}")]
    return "\n".join(lines)
