#!/usr/bin/python3
"""slurm.array: a single-node Slurm cluster in this test's own directory runs
`iris-slurm render` (a 4-task job array of sample partitions + a dependent
`iris merge` job), and the merged image must equal a single-process render;
the same for a guided-nee render, whose array waits for the training job that
writes the guide every task reads (afterok).
Then `iris-slurm sweep` runs a 6-command array + report job, and a sweep with a
failing task must end without its report job (afterok).

Brings up munged (as the munge user, key and socket in a temporary folder it
can reach, removed on exit),
slurmctld and slurmd (no systemd; SLURM_CONF points at a generated slurm.conf
with proctrack/linuxproc and select/cons_tres) and tears everything down on
exit, failure or signal. Exits 77 (CTest SKIP_RETURN_CODE) with the reason
when the machine cannot run it: not root, or the Slurm/munge binaries missing.

usage: slurm_array.py WORKDIR IRIS IRIS_SLURM EXR_CLOSE
"""

import os
import pwd
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

SKIP = 77
TIMEOUT = 240.0  # whole test, well inside the CTest TIMEOUT so cleanup always runs


def log(msg):
    print(f"slurm.array: {msg}", flush=True)


def skip(reason):
    print(f"SKIP: slurm.array: {reason}", flush=True)
    sys.exit(SKIP)


class Cluster:
    def __init__(self, root):
        self.root = root
        self.munge_dir = None  # munged's folder (setup_munge), removed by stop()
        self.procs = []  # (name, Popen) started here, stopped in reverse order
        self.env = dict(os.environ)

    def path(self, *p):
        return os.path.join(self.root, *p)

    def start(self, name, argv, **kw):
        logf = open(self.path("log", f"{name}.stdout"), "w")
        p = subprocess.Popen(argv, stdout=logf, stderr=subprocess.STDOUT, env=self.env,
                             start_new_session=True, **kw)
        self.procs.append((name, p))
        log(f"started {name} (pid {p.pid})")
        return p

    def run(self, argv, check=True, timeout=60):
        r = subprocess.run(argv, env=self.env, capture_output=True, text=True, timeout=timeout)
        if check and r.returncode != 0:
            raise RuntimeError(f"{' '.join(argv)} failed ({r.returncode}):\n{r.stdout}{r.stderr}")
        return r

    def dump_logs(self):
        logdir = self.path("log")
        if not os.path.isdir(logdir):
            return
        for name in sorted(os.listdir(logdir)):
            if not name.endswith(".log"):
                continue  # *.stdout repeat the daemons' logs
            with open(os.path.join(logdir, name), errors="replace") as f:
                text = f.read()
            tail = text[-3000:]
            print(f"----- {name} (last {len(tail)} bytes) -----\n{tail}", flush=True)

    def stop(self):
        if any(n == "slurmctld" and p.poll() is None for n, p in self.procs):
            try:
                self.run(["scancel", "--full", "--quiet", "--user=" + pwd.getpwuid(os.getuid()).pw_name],
                         check=False, timeout=15)
            except Exception as e:  # noqa: BLE001 - cleanup must go on
                log(f"scancel: {e}")
        for name, p in reversed(self.procs):
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
                try:
                    p.wait(timeout=15)
                except subprocess.TimeoutExpired:
                    log(f"{name} ignored SIGTERM; killing it")
                    p.kill()
                    p.wait()
            log(f"stopped {name} (exit {p.returncode})")
        self.procs = []
        if self.munge_dir:
            try:  # its log beside the others, then the folder away
                shutil.copy(os.path.join(self.munge_dir, "munged.log"), self.path("log", "munged.log"))
            except OSError:
                pass
            shutil.rmtree(self.munge_dir, ignore_errors=True)
            self.munge_dir = None


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("", 0))
        return s.getsockname()[1]


def node_line():
    """The node as slurmd sees it (real CPUs, sockets, cores, memory)."""
    r = subprocess.run(["slurmd", "-C"], capture_output=True, text=True, timeout=30)
    line = r.stdout.splitlines()[0] if r.returncode == 0 and r.stdout else ""
    if not line.startswith("NodeName="):
        raise RuntimeError(f"slurmd -C printed nothing usable: {r.stdout}{r.stderr}")
    return line.strip()


def setup_munge(c):
    mu = pwd.getpwnam("munge")
    # munged runs as the munge user: its key, socket and log live in a folder
    # of their own under the system's temporary folder, which that user can
    # reach whatever the permissions of the build tree (a clone in a private
    # 0700 folder made munged fail to create its socket)
    d = tempfile.mkdtemp(prefix="iris-slurm-munge-")
    c.munge_dir = d
    key = os.path.join(d, "munge.key")
    subprocess.run(["mungekey", "--create", "--force", f"--keyfile={key}"], check=True, timeout=30)
    # munged insists: key owned by its user, not readable by others; its dirs
    # owned by it and not writable by others
    os.chown(key, mu.pw_uid, mu.pw_gid)
    os.chmod(key, 0o400)
    os.chown(d, mu.pw_uid, mu.pw_gid)
    os.chmod(d, 0o755)
    sock = os.path.join(d, "munge.socket")
    c.start("munged", ["munged", "--foreground", f"--key-file={key}", f"--socket={sock}",
                       f"--pid-file={d}/munged.pid", f"--seed-file={d}/munged.seed",
                       f"--log-file={os.path.join(d, 'munged.log')}", "--force"],
            user=mu.pw_uid, group=mu.pw_gid, extra_groups=[])
    for _ in range(100):
        if os.path.exists(sock):
            break
        time.sleep(0.1)
    else:
        raise RuntimeError("munged did not create its socket")
    r = subprocess.run(f"munge -S {sock} -n | unmunge -S {sock}", shell=True,
                       capture_output=True, text=True, timeout=30)
    if r.returncode != 0:
        raise RuntimeError(f"munge round trip failed: {r.stdout}{r.stderr}")
    return sock


def write_slurm_conf(c, sock):
    host = socket.gethostname().split(".")[0]
    node = node_line()
    # slurmd -C names the node after the host; keep its hardware fields only
    fields = [f for f in node.split() if not f.startswith(("NodeName=", "UpTime="))]
    user = pwd.getpwuid(os.getuid()).pw_name
    for sub in ("state", "spool", "run"):
        os.makedirs(c.path(sub), exist_ok=True)
    conf = f"""# generated by tests/slurm/slurm_array.py
ClusterName=iristest
SlurmctldHost={host}
SlurmUser={user}
SlurmdUser=root
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={sock}
StateSaveLocation={c.path('state')}
SlurmdSpoolDir={c.path('spool')}
SlurmctldPidFile={c.path('run', 'slurmctld.pid')}
SlurmdPidFile={c.path('run', 'slurmd.pid')}
SlurmctldLogFile={c.path('log', 'slurmctld.log')}
SlurmdLogFile={c.path('log', 'slurmd.log')}
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
MinJobAge=600
MailProg=/bin/true
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
KillWait=5
PlugStackConfig={c.path('plugstack.conf')}
NodeName={host} {' '.join(fields)} State=UNKNOWN
PartitionName=iris Nodes={host} Default=YES MaxTime=INFINITE State=UP
"""
    path = c.path("slurm.conf")
    with open(path, "w") as f:
        f.write(conf)
    with open(c.path("plugstack.conf"), "w") as f:
        f.write("")
    return path, host


def wait_node_idle(c, host, timeout=60):
    t0 = time.time()
    state = ""
    while time.time() - t0 < timeout:
        r = c.run(["sinfo", "-h", "-n", host, "-o", "%T"], check=False, timeout=15)
        state = r.stdout.strip()
        if state in ("idle", "mixed", "allocated"):
            return
        time.sleep(0.5)
    raise RuntimeError(f"node {host} did not come up (state '{state}')")


def main():
    if len(sys.argv) != 5:
        print(__doc__, file=sys.stderr)
        return 2
    workdir, iris, iris_slurm, exr_close = (os.path.abspath(p) for p in sys.argv[1:])
    if os.geteuid() != 0:
        skip("needs root (munged runs as the munge user, slurmd as root); not root here")
    missing = [b for b in ("munged", "mungekey", "munge", "unmunge", "slurmctld", "slurmd",
                           "slurmstepd", "sbatch", "squeue", "scontrol", "scancel", "sinfo")
               if not shutil.which(b)]
    if missing:
        skip(f"missing Slurm/munge binaries: {', '.join(missing)} (Debian: slurm-wlm munge)")
    try:
        pwd.getpwnam("munge")
    except KeyError:
        skip("no 'munge' user (Debian's munge package creates it)")

    if os.path.exists(workdir):
        shutil.rmtree(workdir)
    os.makedirs(os.path.join(workdir, "log"))
    os.chmod(workdir, 0o755)
    c = Cluster(workdir)
    deadline = time.time() + TIMEOUT

    def on_signal(sig, _frame):
        raise KeyboardInterrupt(f"signal {sig}")

    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    ok = False
    try:
        t0 = time.time()
        sock = setup_munge(c)
        conf, host = write_slurm_conf(c, sock)
        c.env["SLURM_CONF"] = conf
        c.start("slurmctld", ["slurmctld", "-D", "-c", "-f", conf])
        c.start("slurmd", ["slurmd", "-D", "-f", conf, "-N", host])
        wait_node_idle(c, host)
        log(f"cluster up in {time.time() - t0:.1f} s (node {host})")

        # The image: 4 sample partitions of 16 spp of the Cornell box, and the
        # same render in one process.
        scene = "cornell-box"
        common = [scene, "--width", "48", "--height", "36", "--seed", "7", "--max-depth", "4"]
        merged = os.path.join(workdir, "merged.exr")
        single = os.path.join(workdir, "single.exr")
        r = c.run([iris_slurm, "render", "--workdir", os.path.join(workdir, "job"), "--iris", iris,
                   "-o", merged, "--spp", "16", "--parts", "4", "--cpus-per-task", "1",
                   "--width", "48", "--height", "36", "--wait",
                   "--timeout", str(max(10.0, deadline - time.time() - 60)),
                   "--", scene, "--seed", "7", "--max-depth", "4"],
                  check=False, timeout=TIMEOUT)
        print(r.stdout + r.stderr, flush=True)
        if r.returncode != 0:
            raise RuntimeError(f"iris-slurm render failed ({r.returncode})")
        jobs_log = os.path.join(workdir, "job", "logs")
        tasks = sorted(f for f in os.listdir(jobs_log) if f.startswith("render-") and "final" not in f)
        if len(tasks) != 4:
            raise RuntimeError(f"expected 4 array task logs, found {tasks}")
        r = c.run([iris, "render"] + common + ["--spp", "16", "--variance", "--quiet",
                                                "-o", single], timeout=120)
        r = c.run([exr_close, merged, single], check=False)
        print(r.stdout + r.stderr, flush=True)
        if r.returncode != 0:
            raise RuntimeError("the merged image differs from the single-process render")
        log("merged image equals the single-process render")

        # Guided: training job (writes the guide) -> array (reads it) -> merge.
        gcommon = ["door", "--width", "40", "--height", "30", "--seed", "7", "--max-depth", "6",
                   "--method", "guided-nee"]
        gjob = os.path.join(workdir, "gjob")
        gmerged = os.path.join(workdir, "gmerged.exr")
        gsingle = os.path.join(workdir, "gsingle.exr")
        r = c.run([iris_slurm, "render", "--workdir", gjob, "--iris", iris,
                   "-o", gmerged, "--spp", "8", "--parts", "4", "--cpus-per-task", "1",
                   "--width", "40", "--height", "30", "--wait",
                   "--timeout", str(max(10.0, deadline - time.time() - 60)),
                   "--", "door", "--seed", "7", "--max-depth", "6", "--method", "guided-nee"],
                  check=False, timeout=TIMEOUT)
        print(r.stdout + r.stderr, flush=True)
        if r.returncode != 0 or "training job" not in r.stdout:
            raise RuntimeError(f"iris-slurm render (guided) failed ({r.returncode})")
        glogs = os.listdir(os.path.join(gjob, "logs"))
        if not os.path.exists(os.path.join(gjob, "guide.bin")) or \
                len([f for f in glogs if f.startswith("render-train-")]) != 1:
            raise RuntimeError(f"guided: no guide file or training log ({sorted(glogs)})")
        c.run([iris, "render"] + gcommon + ["--spp", "8", "--variance", "--quiet", "-o", gsingle],
              timeout=120)
        r = c.run([exr_close, gmerged, gsingle], check=False)
        print(r.stdout + r.stderr, flush=True)
        if r.returncode != 0:
            raise RuntimeError("guided: the merged image differs from the single-process render")
        log("guided: training job + array merged equal the single-process render")

        # A generic sweep (the shape of scenes x methods x budgets for iris
        # bench): every task's output and the report job's must appear...
        sweep = os.path.join(workdir, "sweep")
        r = c.run([iris_slurm, "sweep", "--workdir", sweep, "--wait", "--timeout", "60",
                   "--template", iris + " render {scene} --spp {spp} --width 8 --height 8 "
                   "--method {method} --quiet -o {workdir}/{scene}-{method}-{spp}.exr",
                   "--set", "scene=cornell-box", "--set", "method=bsdf,nee,mis", "--set", "spp=1,2",
                   "--report", f"ls {sweep} > {sweep}/report.txt"], check=False, timeout=90)
        print(r.stdout + r.stderr, flush=True)
        outs = [f for f in os.listdir(sweep) if f.endswith(".exr")] if os.path.isdir(sweep) else []
        if r.returncode != 0 or len(outs) != 6 or not os.path.exists(os.path.join(sweep, "report.txt")):
            raise RuntimeError(f"sweep: exit {r.returncode}, outputs {sorted(outs)}")
        # ... and a failing task must cancel the dependent job (afterok)
        bad = os.path.join(workdir, "sweep-fail")
        r = c.run([iris_slurm, "sweep", "--workdir", bad, "--wait", "--timeout", "60",
                   "--template", "test {v} -ne 2", "--set", "v=1,2,3",
                   "--report", f"touch {bad}/report.txt"], check=False, timeout=90)
        print(r.stdout + r.stderr, flush=True)
        if r.returncode != 1 or os.path.exists(os.path.join(bad, "report.txt")):
            raise RuntimeError(f"failing sweep: exit {r.returncode} (want 1), report written: "
                               f"{os.path.exists(os.path.join(bad, 'report.txt'))}")
        log("sweep ran its 6 tasks and report; a failing task cancelled the report job")
        ok = True
        log(f"passed in {time.time() - t0:.1f} s")
    except BaseException as e:  # noqa: BLE001 - report, clean up, fail
        log(f"FAILED: {e}")
    finally:
        c.stop()
        if not ok:
            c.dump_logs()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
