#!/usr/bin/env python3
"""The named fenced blocks of a Markdown page: a block opened by ```<language> <name> (e.g.
```cpp first.cpp, ```text first.out) is the file <name>. Used by the tests that build and run a
page's snippets (docs/getting-started.md): `page_blocks.py PAGE DIR` writes each into DIR."""
import pathlib
import re
import sys

_FENCE = re.compile(r"^```(\w+)[ \t]+(\S+)[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)


def blocks(text):
    """{name: (language, body)} of the page's named blocks, in page order; a name used twice is
    an error."""
    out = {}
    for m in _FENCE.finditer(text):
        language, name, body = m.group(1), m.group(2), m.group(3)
        if name in out:
            raise ValueError(f"the block name {name} is used twice")
        out[name] = (language, body)
    return out


def main(argv):
    if len(argv) != 3:
        print("usage: page_blocks.py PAGE DIR", file=sys.stderr)
        return 2
    found = blocks(pathlib.Path(argv[1]).read_text())
    target = pathlib.Path(argv[2])
    target.mkdir(parents=True, exist_ok=True)
    for name, (_, body) in found.items():
        (target / name).write_text(body)
    print(" ".join(found))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
