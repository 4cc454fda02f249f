"""Trust at the edges (issue 25): which Dask scheduler a study connects to, what frirom
reads back that it wrote (cache entries, results files), operating-system errors on the
results folder, and studies with a failing member.

The study decks are the bundled joint case made coarse (H = 1, 16 samples): a member is
about a second.
"""

import os
import shutil
import socket
import threading
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pytest

from _models import GSI_DECK, coarse_joint_deck
from frirom import InputError
from frirom.cli import main

ROOT = Path(__file__).resolve().parents[1]
JOINT = ROOT / "cases" / "joint"

BASE = coarse_joint_deck(step="0.2", max_step="0.2")


def study_deck(folder: Path, study: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for f in ("M.mtx", "K.mtx", "dofs.txt"):
        shutil.copy(JOINT / f, folder / f)
    deck = folder / "study.toml"
    deck.write_text(BASE + study)
    return deck


class _Listener:
    """A TCP server on localhost that counts connections and answers each with
    ``reply`` bytes (then keeps the connection open until closed)."""

    def __init__(self, reply: bytes = b""):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.port = self.sock.getsockname()[1]
        self.reply, self.connections, self.conns = reply, 0, []
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self):
        while True:
            try:
                c, _ = self.sock.accept()
            except OSError:
                return
            self.connections += 1
            self.conns.append(c)
            if self.reply:
                c.sendall(self.reply)

    def close(self):
        for c in self.conns:
            c.close()
        self.sock.close()


# ---- 1. the trust boundary of distributed runs -------------------------------------------
def test_deck_alone_cannot_choose_a_scheduler(tmp_path, capsys, monkeypatch):
    """A deck naming a scheduler address is refused before any connection unless the user
    names it too (--scheduler, FRIROM_SCHEDULER) or passes --trust-deck-scheduler."""
    monkeypatch.delenv("FRIROM_SCHEDULER", raising=False)
    srv = _Listener()
    try:
        deck = study_deck(tmp_path, f'[study]\nscheduler = "tcp://127.0.0.1:{srv.port}"\n'
                          '[study.parameters]\n"contacts[0].mu" = [0.3, 0.5]\n')
        t0 = time.monotonic()
        assert main(["study", str(deck), "--out", str(tmp_path / "o"), "--quiet"]) == 2
        err = capsys.readouterr().err
        assert time.monotonic() - t0 < 10
        assert srv.connections == 0
        for words in ("study.scheduler", "--scheduler", "FRIROM_SCHEDULER",
                      "--trust-deck-scheduler", "security"):
            assert words in err, (words, err)
        # the deck's own "serial" stays the deck's choice
        deck.write_text(deck.read_text().replace(f"tcp://127.0.0.1:{srv.port}", "serial"))
        from frirom.study import choose_scheduler, load_study
        assert choose_scheduler(load_study(deck).settings, None) == "serial"
        monkeypatch.setenv("FRIROM_SCHEDULER", "local")
        assert choose_scheduler(load_study(deck).settings, None) == "local"
    finally:
        srv.close()


@pytest.mark.slow
def test_not_a_scheduler_fails_fast(tmp_path, capsys, monkeypatch):
    """A port that answers like no Dask scheduler (eight 0xff bytes: a first message of
    2^64 - 1 bytes, as an HTTP or SSH banner read as a length is) is refused within
    seconds, naming the address, without allocating what it announces; a port that says
    nothing is refused after the connect timeout."""
    import frirom.study as fs
    monkeypatch.delenv("FRIROM_SCHEDULER", raising=False)
    deck = study_deck(tmp_path, '[study]\n[study.parameters]\n"contacts[0].mu" = [0.3]\n')
    for reply, words in ((b"\xff" * 8 + b"SSH-2.0", "announces"),
                         (b"", "no Dask handshake")):
        srv = _Listener(reply)
        monkeypatch.setattr(fs, "CONNECT_TIMEOUT", 1.0, raising=False)
        try:
            addr = f"tcp://127.0.0.1:{srv.port}"
            t0 = time.monotonic()
            code = main(["study", str(deck), "--out", str(tmp_path / "o"), "--quiet",
                         "--scheduler", addr])
            err = capsys.readouterr().err
            assert code == 2 and addr in err and words in err, err
            assert "frirom bug" not in err
            assert time.monotonic() - t0 < 20
        finally:
            srv.close()


def test_probe_accepts_a_real_scheduler():
    """The handshake check passes a real Dask scheduler (an in-process LocalCluster's)."""
    distributed = pytest.importorskip("distributed")
    from frirom.study import probe_scheduler
    with distributed.LocalCluster(n_workers=0, processes=False, protocol="tcp://",
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        probe_scheduler(cluster.scheduler_address, timeout=10.0)


@pytest.mark.parametrize("address", ["tcp://", "tcp://host", "http://host:80",
                                     "tcp://host:99999", "tcp://a b:1", "host:8786",
                                     "tcp://host:8786/../x"])
def test_malformed_scheduler_address(tmp_path, capsys, address):
    """A malformed address is refused when the deck is read (naming study.scheduler) and
    on the command line, before anything connects."""
    deck = study_deck(tmp_path, f'[study]\nscheduler = "{address}"\n'
                      '[study.parameters]\n"contacts[0].mu" = [0.3]\n')
    from frirom.study import load_study
    with pytest.raises(InputError, match="study.scheduler.*tcp://HOST:PORT"):
        load_study(deck)
    deck.write_text(deck.read_text().replace(f'scheduler = "{address}"\n', ""))
    assert main(["study", str(deck), "--out", str(tmp_path / "o"), "--quiet",
                 "--scheduler", address]) == 2
    err = capsys.readouterr().err
    assert "tcp://HOST:PORT" in err and "frirom bug" not in err, err


def test_tls_needs_certificates(tmp_path, capsys, monkeypatch):
    """tls:// without certificates (none given, none in Dask's configuration) is refused
    naming what to give; certificates with a tcp:// address are refused too (they would
    not be used); a missing certificate file is named."""
    pytest.importorskip("distributed")
    monkeypatch.delenv("FRIROM_SCHEDULER", raising=False)
    deck = study_deck(tmp_path, '[study]\n[study.parameters]\n"contacts[0].mu" = [0.3]\n')
    run = ["study", str(deck), "--out", str(tmp_path / "o"), "--quiet"]
    assert main(run + ["--scheduler", "tls://127.0.0.1:9"]) == 2
    assert "--tls-ca" in capsys.readouterr().err
    ca = tmp_path / "ca.pem"
    ca.write_text("not a certificate")
    assert main(run + ["--scheduler", "tcp://127.0.0.1:9", "--tls-ca", str(ca)]) == 2
    assert "tls://" in capsys.readouterr().err
    assert main(run + ["--scheduler", "tls://127.0.0.1:9", "--tls-ca",
                       str(tmp_path / "none.pem")]) == 2
    assert "none.pem" in capsys.readouterr().err


@pytest.mark.parametrize("n", ["-2", "0", "100000"])
def test_worker_count_checked(tmp_path, capsys, n):
    """--workers -2 (and 0, and absurdly many) is refused at once, naming --workers; main
    hung with no worker."""
    deck = study_deck(tmp_path, '[study]\n[study.parameters]\n"contacts[0].mu" = [0.3]\n')
    t0 = time.monotonic()
    assert main(["study", str(deck), "--out", str(tmp_path / "o"), "--quiet",
                 "--workers", n]) == 2
    assert "--workers" in capsys.readouterr().err
    assert time.monotonic() - t0 < 10


# ---- 2. integrity of what frirom reads back -----------------------------------------------
def _rom(rng):
    """A small ReducedModel with a contact pair set (what the cache stores)."""
    import numpy as np
    import scipy.sparse as sp
    from frirom.reduction.interface import ContactPairs
    from frirom.reduction.rom import ReducedModel
    n, n_fe = 6, 12
    A = rng.standard_normal((n, n))
    T = sp.random(n_fe, n, density=0.5, random_state=1, format="csr")
    frames = np.tile(np.eye(3), (2, 1, 1))
    pairs = {"p": ContactPairs(np.array([[0, 1, 2], [3, 4, 5]]), -np.ones((2, 3), int),
                               frames, np.ones((2, 3)))}
    return ReducedModel(K=A @ A.T + n * np.eye(n), M=np.eye(n), T=T,
                        labels=[f"N{i}:UX" for i in range(n)], pairs=pairs,
                        fe_dofs=np.c_[np.arange(n_fe), np.ones(n_fe, int)],
                        node_ids=np.arange(4), node_xyz=rng.standard_normal((4, 3)))


def _edit_cache(path, how):
    import h5py
    import numpy as np
    with h5py.File(path, "a") as h:
        if how == "K*1.5":
            h["K"][...] = 1.5 * h["K"][()]
        elif how == "-frames":
            h["pairs/p/frames"][...] = -h["pairs/p/frames"][()]
        elif how == "NaN in T":
            d = h["T/data"][()]
            d[0] = np.nan
            h["T/data"][...] = d
        elif how == "no checksum":
            del h.attrs["content_sha256"]
        elif how == "external link":
            h["extra"] = h5py.ExternalLink("/etc/hostname", "/")


@pytest.mark.parametrize("how", ["K*1.5", "-frames", "NaN in T", "no checksum",
                                 "external link"])
def test_tampered_cache_entry_is_not_used(tmp_path, how):
    """A cache entry changed after it was written (K scaled, the contact frames negated,
    a NaN in the expansion basis: the edits issue 25 found reused), one without a
    checksum and one with a link is not loaded, and the reason is given; the entry as
    written loads back equal."""
    import numpy as np
    from frirom.reduction.rom import ReducedModel
    rom = _rom(np.random.default_rng(25))
    path = tmp_path / "rom.h5"
    rom.save(path, "fp")
    back = ReducedModel.load(path, "fp")
    assert back is not None and np.array_equal(back.K, rom.K)
    assert np.array_equal(back.pairs["p"].frames, rom.pairs["p"].frames)
    _edit_cache(path, how)
    why = []
    assert ReducedModel.load(path, "fp", why) is None
    assert why and ("checksum" in why[0] or "link" in why[0]), why


@pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx not installed")
def test_tampered_cache_is_rebuilt_through_the_deck(tmp_path):
    """Through a deck: the cache entry's K scaled by 1.5 is noticed, said, and the model
    built again equals the first build (not the scaled one)."""
    import sys
    import numpy as np
    sys.path.insert(0, str(ROOT / "cases" / "models"))
    import block
    from frirom.deck import load_deck
    block.run_ccx(block.write_block_deck(tmp_path / "block.inp", 10, 3, 3, n_ref_modes=0))
    deck = tmp_path / "d.toml"
    deck.write_text(GSI_DECK.format(kt=2.0e8, mu=0.5, h=1))
    first = load_deck(deck)
    entry, = (tmp_path / ".frirom_cache").glob("rom-*.h5")
    _edit_cache(entry, "K*1.5")
    again = load_deck(deck)
    assert not again.reduced.from_cache
    assert any("checksum" in line and str(entry) in line for line in again.log), again.log
    assert np.array_equal(again.reduced.K, first.reduced.K)
    assert load_deck(deck).reduced.from_cache        # the rebuilt entry is good again




@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A finished coarse run of the joint deck: OUT with frf.h5 and deck.toml."""
    folder = tmp_path_factory.mktemp("run")
    deck = study_deck(folder, "")
    (folder / "joint.toml").write_text(deck.read_text())
    out = folder / "out"
    assert main(["run", str(folder / "joint.toml"), "--out", str(out), "--quiet"]) == 0
    return out


def _copy_run(run_dir, tmp_path):
    """A copy of the run's folder (deck, model files, OUT) in tmp_path; its OUT."""
    shutil.copytree(run_dir.parent, tmp_path / "case")
    return tmp_path / "case" / "out"


def _hostile(h5, how):
    """Edit a results file as issue 25's hostile files did."""
    import h5py
    import numpy as np
    with h5py.File(h5, "a") as f:
        if how == "X*1.01":
            f["X"][0] = 1.01 * f["X"][0]
            return
        if "content_sha256" in f.attrs:       # as a file whose run never closed it
            del f.attrs["content_sha256"]
        if how == "bad JSON":
            f.attrs["deck_fingerprint"] = "{not json"
        elif how == "NaN omega":
            f["omega"][1] = np.nan
        elif how == "NaN amp_max":
            f["amp_max"][2, 0] = np.nan
        elif how == "text X":
            del f["X"]
            f["X"] = np.array([b"a", b"b"])
        elif how == "X mis-shaped":
            x = f["X"][()]
            del f["X"]
            f.create_dataset("X", data=x[:, :1, :2], maxshape=(None, 1, 2))
        elif how == "external link":
            f["elsewhere"] = h5py.ExternalLink("/etc/hostname", "/")
        elif how == "nesting":
            g = f
            for i in range(40):
                g = g.create_group(f"g{i}")
        elif how == "int labels":
            f.attrs["group_names"] = np.arange(3)
        elif how == "committed text":
            f.attrs["committed"] = "many"


HOSTILE = [("X*1.01", "checksum"), ("bad JSON", "deck_fingerprint"),
           ("NaN omega", "'omega'"), ("NaN amp_max", "'amp_max'"), ("text X", "'X'"),
           ("X mis-shaped", "'X'"), ("external link", "elsewhere"), ("nesting", "g0"),
           ("int labels", "group_names"), ("committed text", "committed")]


@pytest.mark.parametrize("how,words", HOSTILE, ids=[h for h, _ in HOSTILE])
def test_hostile_results_file_refused(run_dir, tmp_path, capsys, how, words):
    """A results file edited after its run (the checksum), or hostile with no checksum
    (bad JSON, NaN, text or mis-shaped datasets, an external link, deep nesting, wrong
    attribute types) is refused by FRF.load, `frirom show` and `--resume` with the file
    and the field named: exit code 2, never the catch-all, never a plot drawn."""
    from frirom.results import FRF
    out = _copy_run(run_dir, tmp_path)
    h5 = out / "frf.h5"
    FRF.load(h5)                      # the file as written loads
    _hostile(h5, how)
    with pytest.raises(InputError) as e:
        FRF.load(h5)
    assert str(h5) in str(e.value) and words in str(e.value), str(e.value)
    shown = tmp_path / "shown"
    assert main(["show", str(out), "--point", "0", "--dir", str(shown)]) == 2
    err = capsys.readouterr().err
    assert words in err and "frirom bug" not in err, err
    assert not shown.exists() or not list(shown.glob("*.png"))
    assert main(["run", str(out.parent / "joint.toml"), "--out", str(out), "--resume",
                 "--quiet"]) == 2
    err = capsys.readouterr().err
    assert str(h5) in err and "frirom bug" not in err, err


def test_results_checksum_written_and_resealed(run_dir, tmp_path):
    """A closed results file carries its checksum, equal to one recomputed from its
    content (frirom._h5check); a resumed run that extends the file seals it again."""
    import h5py
    from frirom._h5check import DIGEST, content_digest
    out = _copy_run(run_dir, tmp_path)
    with h5py.File(out / "frf.h5", "r") as f:
        assert f.attrs[DIGEST] == content_digest(f)
    deck = out.parent / "joint.toml"
    deck.write_text(deck.read_text().replace("end = 500.0", "end = 505.0"))
    assert main(["run", str(deck), "--out", str(out), "--resume", "--quiet"]) == 0
    with h5py.File(out / "frf.h5", "r") as f:
        assert f.attrs[DIGEST] == content_digest(f) and f["omega"][-1] > 2 * 3.14159 * 500


# ---- 5. an error about a file outside the deck's folder quotes none of it ---------------
def test_error_does_not_echo_a_file_outside_the_deck_folder(tmp_path, capsys):
    """A deck naming a file outside its folder as a matrix gets an error naming that file
    and what was expected, without its first line; the same file inside the deck's folder
    is quoted as before (the quote helps there)."""
    secret = tmp_path / "elsewhere" / "secret.txt"
    secret.parent.mkdir()
    secret.write_text("token: s3cr3t-first-line\n")
    deck = study_deck(tmp_path / "case", "")
    deck.write_text(deck.read_text().replace('stiffness = "K.mtx"',
                                             f'stiffness = "{secret}"'))
    assert main(["run", str(deck), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert str(secret) in err and "MatrixMarket" in err and "s3cr3t" not in err, err
    shutil.copy(secret, tmp_path / "case" / "secret.txt")
    deck.write_text(deck.read_text().replace(str(secret), "secret.txt"))
    assert main(["run", str(deck), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert "s3cr3t" in capsys.readouterr().err


# ---- 3. operating-system errors: the path, what to do, a documented exit code ------------
def test_out_below_a_file_and_h5_a_folder(tmp_path, capsys):
    """--out below a file, and frf.h5 being a folder: exit code 4, the path and what to
    do named, not the catch-all."""
    deck = study_deck(tmp_path / "case", "")
    (tmp_path / "afile").write_text("x")
    assert main(["run", str(deck), "--out", str(tmp_path / "afile" / "sub"),
                 "--quiet"]) == 4
    err = capsys.readouterr().err
    assert "afile" in err and "not a folder" in err and "frirom bug" not in err, err
    out = tmp_path / "o"
    (out / "frf.h5").mkdir(parents=True)
    assert main(["run", str(deck), "--out", str(out), "--quiet"]) == 4
    err = capsys.readouterr().err
    assert "frf.h5" in err and "remove or rename" in err and "frirom bug" not in err, err


def test_read_only_out(tmp_path, capsys, monkeypatch):
    """A read-only --out (the file system refuses the folder: EROFS, simulated, since the
    tests may run as root, whom permissions do not stop): exit code 4 naming the path."""
    import errno
    import pathlib
    deck = study_deck(tmp_path / "case", "")
    real = pathlib.Path.mkdir

    def mkdir(self, *a, **k):
        if "ro" in self.parts:
            raise OSError(errno.EROFS, "Read-only file system", str(self))
        return real(self, *a, **k)
    monkeypatch.setattr(pathlib.Path, "mkdir", mkdir)
    assert main(["run", str(deck), "--out", str(tmp_path / "ro" / "o"), "--quiet"]) == 4
    err = capsys.readouterr().err
    assert str(tmp_path / "ro") in err and "read-only" in err, err


@pytest.mark.slow
def test_full_disk_keeps_every_committed_point(tmp_path, capsys, monkeypatch):
    """The disk fills up at the 6th point (ENOSPC from the writer, simulated): exit code 4
    naming frf.h5 and --resume, no crash; the 5 committed points are in the file, and
    --resume once space is back ends on the uninterrupted run's points exactly."""
    import errno
    import numpy as np
    from frirom.results import FRF, FRFWriter
    deck = study_deck(tmp_path / "case", "")
    ref = tmp_path / "ref"
    assert main(["run", str(deck), "--out", str(ref), "--quiet"]) == 0
    full = FRF.load(ref / "frf.h5")
    real = FRFWriter._append
    count = [0]

    def append(self, p):
        count[0] += 1
        if count[0] == 6:
            raise OSError(errno.ENOSPC, "No space left on device", str(self.path))
        return real(self, p)
    monkeypatch.setattr(FRFWriter, "_append", append)
    out = tmp_path / "o"
    assert main(["run", str(deck), "--out", str(out), "--quiet"]) == 4
    err = capsys.readouterr().err
    assert "frf.h5" in err and "no space" in err and "--resume" in err, err
    assert "frirom bug" not in err
    kept = FRF.load(out / "frf.h5")
    assert len(kept) == 5 and np.array_equal(kept.omega, full.omega[:5])
    monkeypatch.setattr(FRFWriter, "_append", real)
    assert main(["run", str(deck), "--out", str(out), "--resume", "--quiet"]) == 0
    again = FRF.load(out / "frf.h5")
    assert np.array_equal(again.omega, full.omega) and np.array_equal(again.X, full.X)


def test_two_studies_on_one_folder(tmp_path, capsys):
    """A second study on a folder another study is writing is refused at once (exit 2,
    naming the folder); main waited two minutes per member, then failed."""
    from frirom._resume import ResultsLock
    deck = study_deck(tmp_path, '[study]\nscheduler = "serial"\n[study.parameters]\n'
                      '"contacts[0].mu" = [0.3, 0.5]\n')
    out = tmp_path / "o"
    out.mkdir()
    lock = ResultsLock(out)
    try:
        t0 = time.monotonic()
        assert main(["study", str(deck), "--out", str(out), "--quiet"]) == 2
        err = capsys.readouterr().err
        assert str(out) in err and "another frirom run" in err, err
        assert time.monotonic() - t0 < 30
        assert not (out / "members").exists()
    finally:
        lock.release()


# ---- 4. studies that survive a bad member ------------------------------------------------
@pytest.mark.slow
def test_a_failing_member_does_not_stop_the_study(tmp_path, capsys):
    """Member m001's deck cannot be built (a DoF label the model lacks, found only when
    that member runs): the other members run and are kept, each equal to its deck run
    alone; m001 is recorded with its message (failed.json, study.h5) and named in the
    summary; exit code 5."""
    import h5py
    import numpy as np
    from frirom.results import FRF
    deck = study_deck(tmp_path, '[study]\nscheduler = "serial"\n[study.parameters]\n'
                      '"excitation.load[0].dof" = ["tip:x", "nosuch:x", "platform:x"]\n')
    out = tmp_path / "o"
    assert main(["study", str(deck), "--out", str(out), "--quiet"]) == 5
    captured = capsys.readouterr()
    text = captured.out + captured.err
    assert "1 of 3 members failed" in text and "m001" in text and "nosuch:x" in text, text
    for name, dof in (("m000", "tip:x"), ("m002", "platform:x")):
        assert (out / "members" / name / "member.json").is_file()
        alone = tmp_path / f"alone_{name}.toml"
        alone.write_text(BASE.replace('dof = "tip:x"', f'dof = "{dof}"'))
        assert main(["run", str(alone), "--out", str(tmp_path / name), "--quiet"]) == 0
        a = FRF.load(tmp_path / name / "frf.h5")
        b = FRF.load(out / "members" / name / "frf.h5")
        assert np.array_equal(a.omega, b.omega) and np.array_equal(a.X, b.X)
    assert "nosuch:x" in (out / "members" / "m001" / "failed.json").read_text()
    with h5py.File(out / "study.h5", "r") as f:
        assert "nosuch:x" in f["members/m001"].attrs["failed"]
        assert "omega" in f["members/m002"]


def test_study_size_shown_and_limited(tmp_path, capsys):
    """A study of 1 000 000 members (1000 x 1000 values) is refused at once, naming the
    count and --force; a small study shows its size before it starts."""
    vals = ", ".join(f"{0.1 + i * 1e-4:.4f}" for i in range(1000))
    deck = study_deck(tmp_path, '[study]\nscheduler = "serial"\n[study.parameters]\n'
                      f'"contacts[0].mu" = [{vals}]\n"contacts[0].kt" = [{vals}]\n')
    t0 = time.monotonic()
    assert main(["study", str(deck), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "1000000 members" in err and "--force" in err, err
    assert time.monotonic() - t0 < 20
