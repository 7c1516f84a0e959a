"""The pins an extra adds to a lock file: `python .ci/lock_extra.py REPORT LOCK` prints
`name==version` for every distribution of pip's installation report (pip install --dry-run
--report REPORT) that LOCK does not pin yet, the project itself left out. `make lock` appends
them for the `rl` extra, which it resolves without installing (torch's wheels are gigabytes)."""

import json
import re
import sys


def key(name: str) -> str:
    """A distribution's name as pip compares them (PEP 503)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def added_pins(report: dict, lock_lines: list[str], project: str = "playroom") -> list[str]:
    held = {key(line.split("==")[0]) for line in lock_lines if "==" in line}
    found = [item["metadata"] for item in report["install"]]
    return sorted(
        f"{m['name']}=={m['version']}" for m in found if key(m["name"]) not in held | {project}
    )


if __name__ == "__main__":
    report_path, lock_path = sys.argv[1:3]
    with open(report_path) as report, open(lock_path) as lock:
        pins = added_pins(json.load(report), lock.read().splitlines())
    sys.stdout.write("".join(f"{pin}\n" for pin in pins))
