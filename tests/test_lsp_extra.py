"""``bgr lsp`` without its optional extra says how to get it (pygls is not a dependency of the
package, only of ``bgr[lsp]``)."""

from __future__ import annotations

import subprocess
import sys


def test_bgr_lsp_without_pygls_is_a_clear_error():
    # a Python where importing pygls fails, as it does where the extra is not installed
    code = (
        "import sys; sys.modules['pygls'] = None; sys.modules['lsprotocol'] = None\n"
        "from bgr.cli import main; sys.exit(main(['lsp']))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 1
    assert "pip install 'bgr[lsp]'" in done.stderr
    assert "Traceback" not in done.stderr
