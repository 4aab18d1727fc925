#!/usr/bin/env python3
"""Print the layout of an amytiss policy file (docs/policy_file.md) using h5py.

usage: inspect_policy.py POLICY.h5

Prints the root attributes (those every file has, then the optional ones present, sorted), then
one line per dataset: its path, element type and shape, and a V_0 summary. Filters follow the
shape: shuffle, gzip(level), fletcher32. Exits 1 when the file is not an amytiss policy. Used by
test_cli to show that Python opens the files the C++ core writes.
"""
import sys

import h5py
import numpy as np


def text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    with h5py.File(argv[1], "r") as policy_file:
        attributes = policy_file.attrs
        if text(attributes.get("format", "")) != "amytiss-policy":
            print(f"error: {argv[1]} is not an amytiss policy", file=sys.stderr)
            return 1
        required = ("format", "format_version", "config_hash", "computed_by", "run_id", "engine_version",
                    "horizon", "spec", "content_digest")
        for name in required:
            print(f"attribute {name} = {text(attributes[name])}")
        # The attributes only some files have (stationary, iterations, converged, guarantee).
        for name in sorted(set(attributes) - set(required)):
            print(f"attribute {name} = {text(attributes[name])}")

        datasets = []
        policy_file.visititems(
            lambda name, item: datasets.append((name, item)) if isinstance(item, h5py.Dataset) else None)
        for name, dataset in sorted(datasets):
            kind = "string" if h5py.check_string_dtype(dataset.dtype) else str(dataset.dtype)
            filters = " shuffle" if dataset.shuffle else ""
            filters += f" {dataset.compression}({dataset.compression_opts})" if dataset.compression else ""
            filters += " fletcher32" if dataset.fletcher32 else ""
            print(f"dataset /{name} {kind} {tuple(dataset.shape)}{filters}")

        values = policy_file["values"][0]
        roles = policy_file["roles"][()]
        free = values[roles == 0]
        if free.size:
            print(f"V_0 free cells {free.size}: min {free.min():.6f} mean {free.mean():.6f} "
                  f"max {free.max():.6f}")
        config_text = policy_file["config"].asstr()[()]
        print(f"config first line: {config_text.splitlines()[0] if config_text else ''}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
