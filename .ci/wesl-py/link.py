#!/usr/bin/env python3
"""Link WESL against lodkit's WESL package with wesl-py, which bundles wesl-rs (the linker
Bevy 0.20 runs), as a wesl-rs user would: the package folder is a dependency named `lodkit`.

    python link.py PACKAGE_DIR JOBS.json

PACKAGE_DIR is shader_lib/wesl/lodkit. JOBS.json is the same array wesl-link.mjs reads:
{"root": "<WESL source of package::main>", "conditions": {"NAME": true}, "out": "<path>"}.
Exit: 0 all linked, 1 some job failed (its error on stderr), 2 usage error.
"""

import json
import sys
from pathlib import Path

import wesl


def main() -> int:
    if len(sys.argv) != 3:
        print("usage: python link.py PACKAGE_DIR JOBS.json", file=sys.stderr)
        return 2
    package, jobs_file = Path(sys.argv[1]), Path(sys.argv[2])
    if not (package / "wesl.toml").is_file():
        print(f"link.py: no wesl.toml in {package}", file=sys.stderr)
        return 2
    jobs = json.loads(jobs_file.read_text())
    failed = 0
    for job in jobs:
        try:
            result = wesl.compile(
                {"package::main": job["root"]},
                features=job.get("conditions", {}),
                dependencies={"lodkit": str(package)},
            )
            Path(job["out"]).write_text(result.wgsl)
        except wesl.CompileError as e:
            failed += 1
            print(f"{job['out']}: {e}", file=sys.stderr)
    print(f"wesl-py {wesl.__version__}: linked {len(jobs) - failed} of {len(jobs)}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
