"""Commands run on a genuinely small file system: a tmpfs of its own, mounted in a private
mount namespace (``unshare --mount``, as root with CAP_SYS_ADMIN, or with ``--map-root-user``
as any user where user namespaces are allowed), so nothing outside the test sees it and it
vanishes with the namespace.

``on_small_disk`` runs this file as a script inside the namespace: it mounts the tmpfs on
``DISK``, fills it with a file ``filler`` until ``free_kib`` remain, runs each ``landnav``
command (a process of its own, its working folder the disk's parent), and prints as JSON each
command's exit code and standard error and every path then on the disk (the filler apart). The
file system fails a write with ``ENOSPC`` as a full disk does, through every real writer
(pyarrow, matplotlib, the campaign's lock and parts)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

NO_MOUNT = 77  # the script's exit code when the tmpfs cannot be mounted
_CHUNK = 1 << 16


def _fill(disk: Path, free_kib: int) -> None:
    """Write ``disk/filler`` until ``free_kib`` KiB of the file system remain."""
    info = os.statvfs(disk)
    left = max(info.f_bavail * info.f_frsize - free_kib * 1024, 0)
    with open(disk / "filler", "wb") as handle:
        try:
            while left > 0:
                left -= handle.write(b"\0" * min(left, _CHUNK))
                handle.flush()
        except OSError:  # already full
            pass


def _on_disk(disk: Path) -> list[str]:
    return sorted(str(p.relative_to(disk)) for p in disk.rglob("*") if p.name != "filler")


def _inside(spec: dict) -> int:
    disk = Path(spec["disk"])
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={spec['size_kib']}k",
                              "tmpfs", str(disk)], capture_output=True, text=True)
    if mounted.returncode != 0:
        print(json.dumps({"no_mount": mounted.stderr.strip()}))
        return NO_MOUNT
    _fill(disk, spec["free_kib"])
    (disk / "tmp").mkdir()
    env = {**os.environ, **spec["env"],
           "TMPDIR": str(disk / "tmp") if spec["tmp_on_disk"] else spec["env"]["TMPDIR"]}
    results = []
    for k, args in enumerate(spec["commands"]):
        if k and spec["free_before_next"]:
            (disk / "filler").unlink(missing_ok=True)
        done = subprocess.run([sys.executable, "-m", "simulator.cli", *args], cwd=disk.parent,
                              env=env, capture_output=True, text=True, timeout=900)
        results.append({"code": done.returncode, "stdout": done.stdout, "stderr": done.stderr,
                        "left": _on_disk(disk)})
    print(json.dumps({"results": results}))
    return 0


def _namespaces() -> list[list[str]]:
    """The ``unshare`` commands to try, the plainest first."""
    unshare = shutil.which("unshare")
    if unshare is None:
        return []
    plain = [unshare, "--mount", "--propagation", "private"]
    return [plain, [*plain, "--map-root-user"]] if os.geteuid() == 0 else [
        [*plain, "--map-root-user"]]


def on_small_disk(commands: list[list[str]], disk: Path, env: dict[str, str], free_kib: int,
                  size_kib: int = 4096, tmp_on_disk: bool = True,
                  free_before_next: bool = False) -> list[dict] | str:
    """Run each ``landnav`` command of ``commands`` in ``disk.parent`` with a tmpfs of
    ``size_kib`` KiB on the empty folder ``disk``, ``free_kib`` of it free (the temporary
    folder ``disk/tmp`` with ``tmp_on_disk``; with ``free_before_next`` the filler is removed
    before each command after the first). Returns each command's ``code``, ``stdout``,
    ``stderr`` and the paths ``left`` on the disk afterwards; or, when no tmpfs can be mounted
    here, why."""
    spec = json.dumps({"disk": str(disk), "size_kib": size_kib, "free_kib": free_kib,
                       "tmp_on_disk": tmp_on_disk, "free_before_next": free_before_next,
                       "env": env, "commands": commands})
    why = "no unshare (util-linux) to make a private mount namespace"
    for prefix in _namespaces():
        done = subprocess.run([*prefix, sys.executable, __file__, spec], capture_output=True,
                              text=True, timeout=1800)
        if done.returncode == 0:
            return json.loads(done.stdout)["results"]
        if done.returncode == NO_MOUNT:
            reason = json.loads(done.stdout)["no_mount"]
        elif done.stderr.startswith("unshare:"):  # no namespace for this process
            reason = done.stderr.strip()
        else:
            raise AssertionError(f"the small-disk script failed: {done.stderr}")
        why = f"cannot mount a small tmpfs here ({' '.join(prefix[1:])}): {reason}"
    return why


if __name__ == "__main__":
    sys.exit(_inside(json.loads(sys.argv[1])))
