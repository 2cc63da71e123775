"""The block reader of tests/docs/blocks.py on small documents (what the doc runner relies on)."""
from tests.docs.blocks import blocks

DOC = """# t

```sh
make demo     # comment
.venv/bin/ftcsim export-ssp x --out y   # again: refused, exit 2
#   ftcsim: error: command line: --out: y exists
ls \\
  -l
```

<!-- not-run: needs the network -->
```console
$ git clone https://example.org/x
```

<!-- file: build/tut/x.py -->
```python
print(1)
```

```console
$ ftcsim run bad.toml
ftcsim: error: bad.toml: x: y
$ false
$ echo $?
1
$ ./host a \\
    b
t=0 ok   (rc 0)
```

```toml
a = 1
```
"""


def test_blocks_markers_and_expected_status(tmp_path):
    p = tmp_path / "d.md"
    p.write_text(DOC)
    bs = blocks(p)
    assert [b.lang for b in bs] == ["sh", "console", "python", "console", "toml"]
    sh, net, py, con, _ = bs
    assert [(c.text.split()[0], c.expect) for c in sh.commands] == [("make", 0), (".venv/bin/ftcsim", 2), ("ls", 0)]
    assert sh.commands[2].text == "ls \\\n  -l"
    assert net.skip == "needs the network" and py.file == "build/tut/x.py" and py.text == "print(1)\n"
    assert [c.expect for c in con.commands] == [2, 1, 0, 0]
    assert con.commands[3].text == "./host a \\\n    b" and sh.line == 3
