#!/usr/bin/env python3
"""docs/CONFIG.md's key reference is a snapshot of `seamless_config_keys` (the structs' own
descriptions): every row the generator prints must be in the document, word for word, and the
document must list no key the structs no longer have. A key added without regenerating the
snapshot fails here (five had gone missing before this test existed)."""
import subprocess
import sys


def key_rows(text):
    """The key reference's rows by key (first cell), from a Markdown table."""
    rows = {}
    for line in text.splitlines():
        if line.startswith("| `"):
            rows[line.split("|")[1].strip()] = line.rstrip()
    return rows


def main():
    keys_binary, doc = sys.argv[1], sys.argv[2]
    generated = key_rows(subprocess.run([keys_binary], check=True, capture_output=True, text=True).stdout)
    with open(doc, encoding="utf-8") as f:
        text = f.read()
    documented = key_rows(text[text.index("## Key reference"):])  # the document's other tables are not keys
    if not generated:
        print("seamless_config_keys printed no key rows")
        return 1
    missing = [k for k in generated if k not in documented]
    stale = [k for k in documented if k not in generated]
    changed = [k for k in generated if k in documented and documented[k] != generated[k]]
    for what, ks in (("missing from", missing), ("no longer in the structs but in", stale),
                     ("described differently in", changed)):
        for k in ks:
            print(f"{k}: {what} {doc}")
    if missing or stale or changed:
        print(f"regenerate the table: seamless config --list (or {keys_binary}) and paste it into {doc}")
        return 1
    print(f"{len(generated)} keys, all documented as generated")
    return 0


if __name__ == "__main__":
    sys.exit(main())
