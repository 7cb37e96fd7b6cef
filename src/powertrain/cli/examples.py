"""``powertrain examples``: copy the shipped engines, mounts and examples into a folder."""

from __future__ import annotations

import filecmp
import shutil
from pathlib import Path

import click

from powertrain.cli.common import quiet_option, say
from powertrain.cli.group import main
from powertrain.data import FOLDERS, shipped_files
from powertrain.errors import InputError
from powertrain.outputs import atomic_path


@main.command()
@click.argument("folder", type=click.Path(file_okay=True, dir_okay=True))
@quiet_option
def examples(folder, quiet):
    """Copy the shipped files into FOLDER/engines, FOLDER/mounts and FOLDER/examples.

    \b
    The guides' commands name these files, e.g.
      examples/measured-runup.csv
      engines/default-modal-body.toml
      mounts/hydraulic-engine-mount-z.toml
    After a wheel install they are inside the package; this command puts a copy where the
    commands find them. An existing file is never overwritten: a file identical to the
    shipped one is left as it is, a different one stops the command before anything is
    copied.

    \b
    Examples:
      powertrain examples .
      powertrain examples ~/powertrain-tour && cd ~/powertrain-tour
    """
    root = Path(folder)
    if root.exists() and not root.is_dir():
        raise InputError("exists and is not a folder; nothing copied", file=root, key="FOLDER")
    pairs = [(src, root / name / src.name) for name in FOLDERS for src in shipped_files(name)]
    for src, dest in pairs:
        _check_free(src, dest, InputError)
    copied = [dest for src, dest in pairs if not dest.exists()]
    for src, dest in pairs:
        if dest in copied:
            with atomic_path(dest) as tmp:
                shutil.copyfile(src, tmp)
    kept = len(pairs) - len(copied)
    say(f"copied {len(copied)} files into {root}/{{{','.join(FOLDERS)}}}"
        + (f"; {kept} identical files were there already" if kept else ""), quiet)


def _check_free(src: Path, dest: Path, error) -> None:
    """Refuse a destination that exists and is not a copy of the shipped file ``src``."""
    if dest.parent.exists() and not dest.parent.is_dir():
        raise error("exists and is not a folder; nothing copied", file=dest.parent, key="FOLDER")
    if dest.exists() and not dest.is_file():
        raise error("exists and is not a file; nothing copied", file=dest, key="FOLDER")
    if dest.exists() and not filecmp.cmp(src, dest, shallow=False):
        raise error("exists and differs from the shipped file; powertrain examples never "
                    "overwrites (move it or choose another folder); nothing copied", file=dest, key="FOLDER")
