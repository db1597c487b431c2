#!/usr/bin/env python3
"""Fails if the CLI reaches into the server's internals.

Usage: cli_layers_test.py CLI_DIR SERVER_DIR CORE_DIR PROTO_DIR

Every "..." include of every file under CLI_DIR must name a file of CLI_DIR itself, of core/, of proto/
(balloon::contract), a generated balloon/v1/*.pb.h or google/rpc/*.pb.h, or one of the server/ folders the CLI links as targets
(ALLOWED_SERVER_FOLDERS: embedded/ is balloon::embedded, jobs/ is balloon::jobs). rpc/, service/, store/,
http/, net/ fail, but for the files of ALLOWED_SERVER_FILES.
Prints one line per violation and exits 1, or prints what it checked and exits 0.
"""
import pathlib
import re
import sys

ALLOWED_SERVER_FOLDERS = {"embedded", "jobs"}
# Shared with the service until it moves where both sides use it (typed reports <-> the jobs layer's outcomes).
ALLOWED_SERVER_FILES = {"service/job_reports.hpp"}
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')
SOURCE_SUFFIXES = {".hpp", ".cpp", ".h", ".cc"}


def main() -> int:
    if len(sys.argv) != 5:
        print("usage: cli_layers_test.py CLI_DIR SERVER_DIR CORE_DIR PROTO_DIR", file=sys.stderr)
        return 2
    cli, server, core, proto = (pathlib.Path(a).resolve() for a in sys.argv[1:])
    files = sorted(p for p in cli.rglob("*") if p.is_file() and p.suffix in SOURCE_SUFFIXES)
    problems = []
    includes = 0
    for path in files:
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
            match = INCLUDE.match(line)
            if not match:
                continue
            includes += 1
            included = match.group(1)
            where = f"{path.relative_to(cli)}:{number}: #include \"{included}\""
            if any((root / included).is_file() for root in (path.parent, core, proto)):
                continue
            if included.startswith(("balloon/v1/", "google/rpc/")) and included.endswith(".pb.h"):
                continue
            folder = included.split("/")[0]
            if (server / included).is_file() and (folder in ALLOWED_SERVER_FOLDERS or included in ALLOWED_SERVER_FILES):
                continue
            if (server / included).is_file():
                problems.append(f"{where}: server/{folder}/ is the server's inside; the CLI uses "
                                f"{sorted(ALLOWED_SERVER_FOLDERS)} only")
            else:
                problems.append(f"{where}: not a file of the CLI, core/, the allowed server/ folders or generated code")
    for problem in problems:
        print(problem)
    if problems:
        print(f"cli_layers_test: {len(problems)} violation(s) in {len(files)} files")
        return 1
    print(f"cli_layers_test: {len(files)} files, {includes} includes, no violation")
    return 0


if __name__ == "__main__":
    sys.exit(main())
