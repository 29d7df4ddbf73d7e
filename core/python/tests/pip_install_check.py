#!/usr/bin/python3
"""`pip install .` into a fresh venv (--system-site-packages, offline:
--no-build-isolation --no-index), as the README says, then import idcol from
another directory and check the version, the stubs and one solve.

usage: pip_install_check.py SOURCE_DIR   (run by ctest as python.pip_install)
"""
import os
import re
import subprocess
import sys
import tempfile


def main():
    src = os.path.abspath(sys.argv[1])
    try:
        import ensurepip  # noqa: F401  (Debian: python3-venv)
    except ImportError:
        print("pip_install_check: skipped, this interpreter cannot make a venv with pip (python3-venv)")
        sys.exit(77)
    with open(os.path.join(src, "CMakeLists.txt")) as f:
        version = re.search(r"project\(\s*idcol\s+VERSION\s+([0-9.]+)", f.read()).group(1)
    with tempfile.TemporaryDirectory(prefix="idcol-pip-") as tmp:
        venv = os.path.join(tmp, "venv")
        subprocess.check_call([sys.executable, "-m", "venv", "--system-site-packages", venv])
        py = os.path.join(venv, "bin", "python")
        subprocess.check_call([py, "-m", "pip", "install", "-q", "--no-build-isolation", "--no-index", src])
        elsewhere = os.path.join(tmp, "elsewhere")
        os.mkdir(elsewhere)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        code = (
            "import os, idcol, numpy as np\n"
            "assert idcol.__file__.startswith(%r), idcol.__file__\n"
            "assert idcol.__version__ == %r, idcol.__version__\n"
            "d = os.path.dirname(idcol.__file__)\n"
            "assert os.path.exists(os.path.join(d, 'py.typed'))\n"
            "assert os.path.exists(os.path.join(d, '__init__.pyi'))\n"
            "r = idcol.solve(idcol.Sphere(1.0), idcol.Sphere(1.0), np.eye(3, dtype=np.float32), [3.0, 0, 0])\n"
            "assert r.converged and abs(r.alpha - 1.5) < 1e-12, r\n"
            "print('installed', idcol.__version__, d)\n" % (venv, version))
        out = subprocess.run([py, "-c", code], cwd=elsewhere, env=env, capture_output=True, text=True)
        sys.stdout.write(out.stdout)
        sys.stderr.write(out.stderr)
        if out.returncode != 0:
            sys.exit("pip_install_check: the installed package failed (exit %d)" % out.returncode)


if __name__ == "__main__":
    main()
