#!/usr/bin/env python3
"""Writes Wycheproof's ECDSA P-256 SHA-256 vectors (IEEE P1363 signatures)
as C++ initialisers for the on-target test "wycheproof"
(WycheproofTest.cpp): the controller's own mbedTLS build checks them all.

    wycheproof_table.py <vectors.json> <output.inc>
"""
import json
import sys


def byte_list(hex_text):
    return ", ".join(f"0x{hex_text[i:i + 2]}" for i in range(0, len(hex_text), 2)) or "0"


def main():
    source, output = sys.argv[1], sys.argv[2]
    with open(source, encoding="utf-8") as handle:
        vectors = json.load(handle)
    keys = []
    cases = []
    for group in vectors["testGroups"]:
        if group["key"]["curve"] != "secp256r1" or group["sha"] != "SHA-256":
            raise SystemExit(f"{source}: a group that is not P-256 with SHA-256")
        keys.append(group["key"]["uncompressed"])
        for test in group["tests"]:
            result = {"valid": 0, "invalid": 1, "acceptable": 2}[test["result"]]
            cases.append((test["tcId"], result, len(keys) - 1, test["msg"], test["sig"]))
    lines = [f"// Generated from {source} by tests_renode/target/wycheproof_table.py; do not edit.",
             f"constexpr size_t kWycheproofKeys = {len(keys)};",
             f"constexpr size_t kWycheproofCases = {len(cases)};",
             "constexpr uint8_t kWycheproofKey[kWycheproofKeys][65] = {"]
    for key in keys:
        if len(key) != 130:
            raise SystemExit(f"{source}: a key that is not 65 bytes")
        lines.append(f"    {{{byte_list(key)}}},")
    lines.append("};")
    lines.append("constexpr WycheproofCase kWycheproof[kWycheproofCases] = {")
    for tc_id, result, key, message, signature in cases:
        lines.append(f"    {{{tc_id}, {result}, {key}, {len(message) // 2}, {{{byte_list(message)}}}, "
                     f"{len(signature) // 2}, {{{byte_list(signature)}}}}},")
    lines.append("};")
    with open(output, "w", encoding="ascii") as handle:
        handle.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
