"""docs/getting-started.md's Python script (the block ```python first.py) runs and prints the
page's output (the block ```text first-py.out), so the page cannot go stale. Its C++ programs are
built and run against an installed kinetic by the suite's install_relocated_examples."""

import importlib.util
import os
import subprocess
import sys

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")


def page_blocks():
    spec = importlib.util.spec_from_file_location(
        "page_blocks", os.path.join(ROOT, "tests", "packaging", "page_blocks.py")
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    with open(os.path.join(ROOT, "docs", "getting-started.md"), encoding="utf-8") as f:
        return module.blocks(f.read())


def test_the_first_python_script_prints_the_pages_output(tmp_path):
    blocks = page_blocks()
    language, script = blocks["first.py"]
    assert language == "python"
    (tmp_path / "first.py").write_text(script)
    done = subprocess.run(
        [sys.executable, "first.py"], cwd=tmp_path, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == blocks["first-py.out"][1].strip()
