#!/usr/bin/env python3
"""Fails if core/ reaches above itself or a core/ folder includes one above it.

Usage: core_layers_test.py CORE_DIR

Every #include of every file under CORE_DIR is read:
- <...> includes of gRPC, protobuf, SQLite or cpp-httplib fail (core has no transport and no store);
- "..." includes must name a file of core/ itself (so nothing of server/ or client/, nor a generated
  balloon/v1/*.pb.h);
- a folder may include only itself and the folders below it (LOWER_FOLDERS, the order of the CMake
  targets balloon_core_<folder> in core/CMakeLists.txt). The headers at the top of core/ (result.hpp,
  progress.hpp) belong to the lowest target, mesh.
Prints one line per violation and exits 1, or prints what it checked and exits 0.
"""
import pathlib
import re
import sys

# Folder -> the folders it may include besides itself. One-way: no folder appears below itself.
LOWER_FOLDERS = {
    "mesh": set(),
    "material": {"mesh"},
    "fem": {"mesh", "material"},
    "solve": {"mesh", "material", "fem"},
    "calibration": {"mesh", "material", "fem", "solve"},
    "design": {"mesh", "material", "fem", "solve"},
}
FORBIDDEN_SYSTEM = re.compile(r"^(grpc|grpcpp|grpc\+\+|google/protobuf|google/rpc|sqlite3|httplib)\b|\.pb\.h$")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')
SOURCE_SUFFIXES = {".hpp", ".cpp", ".h", ".cc", ".hh", ".cxx", ".inl"}


def folder_of(core: pathlib.Path, path: pathlib.Path) -> str:
    parts = path.relative_to(core).parts
    return parts[0] if len(parts) > 1 else "mesh"  # top-level headers belong to the lowest target


def main() -> int:
    if len(sys.argv) != 2:
        print("usage: core_layers_test.py CORE_DIR", file=sys.stderr)
        return 2
    core = pathlib.Path(sys.argv[1]).resolve()
    if not core.is_dir():
        print(f"core_layers_test: '{core}' is not a directory", file=sys.stderr)
        return 2
    files = sorted(p for p in core.rglob("*") if p.is_file() and p.suffix in SOURCE_SUFFIXES)
    problems = []
    includes = 0
    for path in files:
        name = path.relative_to(core)
        folder = folder_of(core, path)
        if folder not in LOWER_FOLDERS:
            problems.append(f"{name}: folder '{folder}' has no place in the layer order (add it to LOWER_FOLDERS)")
            continue
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
            match = INCLUDE.match(line)
            if not match:
                continue
            includes += 1
            bracket, included = match.groups()
            where = f"{name}:{number}: #include {bracket}{included}{'>' if bracket == '<' else chr(34)}"
            if FORBIDDEN_SYSTEM.search(included):
                problems.append(f"{where}: core includes no gRPC, protobuf, SQLite or HTTP headers")
                continue
            if bracket == "<":
                continue
            target = (core / included) if (core / included).is_file() else (path.parent / included)
            if not target.is_file() or core not in target.resolve().parents:
                problems.append(f"{where}: not a file of core/ (core includes nothing of server/, client/ "
                                "or generated code)")
                continue
            to = folder_of(core, target.resolve())
            if to != folder and to not in LOWER_FOLDERS.get(folder, set()):
                problems.append(f"{where}: {folder}/ may include only {sorted(LOWER_FOLDERS[folder] | {folder})}, "
                                f"not {to}/")
    for problem in problems:
        print(problem)
    if problems:
        print(f"core_layers_test: {len(problems)} violation(s) in {len(files)} files")
        return 1
    print(f"core_layers_test: {len(files)} files, {includes} includes, no violation")
    return 0


if __name__ == "__main__":
    sys.exit(main())
