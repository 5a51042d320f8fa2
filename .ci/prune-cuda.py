"""Deletes the CUDA files in a venv's site-packages/nvidia that torch never loads on a CPU.

PyPI's torch for Linux x86_64 is the CUDA build (see .ci/requirements-torch.txt): its shared
libraries name CUDA libraries as needed, so those must be installed for `import torch` to work on
a machine without a GPU. But the nvidia wheels also carry 1.2 GB that nothing links against and
that only CUDA work opens at run time with dlopen (cuDNN's engine libraries behind its 1 MB
front, cuSOLVER, nvJitLink, the NVRTC builtins, static archives, headers). CI machines have run
out of disk installing them, so this keeps only the dynamic linker's closure of torch's own
libraries (every nvidia file some loaded library names as DT_NEEDED, transitively) and deletes
the rest. Run after torch is installed; prints what it freed. `import torch` and a CPU matmul
are checked by .ci/python-env afterwards.
"""

import os
import re
import subprocess
import sys


def needed(path):
    """The DT_NEEDED names of one ELF file (readelf, from binutils, which gcc brings)."""
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True, check=True).stdout
    return re.findall(r"\(NEEDED\).*\[(.*)\]", out)


def shared_libraries(root):
    for folder, _, files in os.walk(root):
        for name in files:
            if name.endswith(".so") or ".so." in name:
                yield os.path.join(folder, name)


def main(site):
    nvidia = os.path.join(site, "nvidia")
    by_name = {os.path.basename(p): p for p in shared_libraries(nvidia)}
    pending = list(shared_libraries(os.path.join(site, "torch")))
    loaded = set()
    while pending:
        path = pending.pop()
        if path in loaded:
            continue
        loaded.add(path)
        pending.extend(by_name[n] for n in needed(path) if n in by_name)
    kept = {os.path.realpath(p) for p in loaded}
    freed = 0
    for folder, _, files in os.walk(nvidia):
        for name in files:
            path = os.path.join(folder, name)
            # Python files keep the nvidia packages importable (torch looks them up by name).
            if name.endswith(".py") or os.path.realpath(path) in kept:
                continue
            freed += os.path.getsize(path) if not os.path.islink(path) else 0
            os.remove(path)
    print(f"prune-cuda: kept {len(kept & {os.path.realpath(p) for p in by_name.values()})} "
          f"CUDA libraries torch links against, freed {freed >> 20} MB")


if __name__ == "__main__":
    main(sys.argv[1])
