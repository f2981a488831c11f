"""Importing jaxcable leaves the caller's JAX configuration alone, and a model built
without float64 says how to enable it. Each check runs in a fresh process: the suite
itself has float64 on."""

import os
import subprocess
import sys
import textwrap


def _run(code: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "JAX_ENABLE_X64"}
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], env=env, capture_output=True, text=True, timeout=120
    )


def test_import_changes_no_global_setting():
    run = _run(
        """
        import jax
        before = jax.config.jax_enable_x64
        import jaxcable
        print(before, jax.config.jax_enable_x64)
        """
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split() == ["False", "False"]


def test_a_model_without_float64_says_how_to_enable_it():
    run = _run(
        """
        import jaxcable as jc
        try:
            jc.LineType(1.0, 0.01, jc.LinearElastic(1e6))
        except jc.Float64Error as error:
            print(error)
        """
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert 'jax.config.update("jax_enable_x64", True)' in run.stdout
    assert "JAX_ENABLE_X64=1" in run.stdout


def test_the_command_line_enables_float64_for_its_own_process():
    run = _run(
        """
        import jax
        from jaxcable._cli import main
        # Refused (2) once JAX is set up: a malformed input would be refused before.
        main(["run", "anchored_line", "--out", "run.xlsx"])
        print(jax.config.jax_enable_x64)
        """
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split()[-1] == "True"
