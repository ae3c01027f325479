# SPDX-License-Identifier: BSD-3-Clause
"""The examples of docs/python.md marked runnable (a ```python block right after the line
`<!-- runnable -->`) run, each in a fresh interpreter in a scratch folder of its own, and
print what their comments say: each `# TEXT` comment after a print() line, or on a line of its
own after the block's prints, must match a line of the output (`...` stands for any text)."""
import os
import re
import subprocess
import sys
import unittest

import support  # first: it skips (status 77) when numpy is absent

DOC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs", "python.md")
MARK = "<!-- runnable -->"


def runnable_blocks():
    """(line number, code) of each marked block."""
    with open(DOC) as f:
        lines = f.read().split("\n")
    blocks = []
    for i, line in enumerate(lines):
        if line.strip() == MARK and i + 1 < len(lines) and lines[i + 1].strip() == "```python":
            end = lines.index("```", i + 2)
            blocks.append((i + 3, "\n".join(lines[i + 2:end])))
    return blocks


def expected_lines(code):
    """The outputs the comments promise: `print(...)  # TEXT`, or `# TEXT` lines that follow
    a print of the block (all but the block's explanatory comments, which precede code)."""
    out = []
    for line in code.split("\n"):
        m = re.search(r"print\(.*\)\s+#\s(.*)$", line)
        if m:
            out.append(m.group(1))
        elif re.match(r"^#\s", line) and out is not None and "print(" in code.split(line)[0]:
            out.append(line[2:])
    return [re.sub(r"\s*\(and .*\)$", "", t) for t in out]


def pattern(text):
    """A regex for a promised line: `...` is any text."""
    return "^" + ".*".join(re.escape(part) for part in text.split("...")) + "$"


class Docs(unittest.TestCase):
    def test_runnable_examples(self):
        blocks = runnable_blocks()
        self.assertGreaterEqual(len(blocks), 3, "no runnable examples found in %s" % DOC)
        for k, (line, code) in enumerate(blocks):
            with self.subTest(line=line):
                folder = support.work("example-%d" % k)
                os.makedirs(folder)
                p = subprocess.run([sys.executable, "-c", code], cwd=folder, text=True,
                                   capture_output=True, env=support.python_env(), timeout=300)
                self.assertEqual(p.returncode, 0, "docs/python.md:%d:\n%s" % (line, p.stderr))
                got = p.stdout.rstrip("\n").split("\n")
                for text in expected_lines(code):
                    self.assertTrue(any(re.match(pattern(text), g) for g in got),
                                    "docs/python.md:%d: no output line like %r in:\n%s"
                                    % (line, text, p.stdout))


if __name__ == "__main__":
    support.main()
