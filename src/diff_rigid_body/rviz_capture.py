"""Headless rviz screenshots of the demo scene, and the pixel checks on them.

Runs under an X server without a screen (``xvfb-run -a -s "-screen 0
1280x800x24"``, software OpenGL: LIBGL_ALWAYS_SOFTWARE=1). Screenshots use
ImageMagick: ``import -window root`` to take one, ``stream`` to read its
pixels into numpy.

Used by ``scripts/rviz_screenshot`` (as ``python3 -m
diff_rigid_body.rviz_capture``: starts ``demo.launch rviz:=true
client:=false`` and saves one PNG) and by the visual rostest
(``test/rostest/clients_rviz.py``).

Colours of the default scene in ``rviz/demo.rviz``: the knot mesh is teal
(lit, so G and B well above R), the vertex markers of nodes/vertex_markers.py
are flat yellow (knot) and magenta (rock), the background is (48, 48, 48).
"""
import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np



def demo_rviz_config():
    """rviz/demo.rviz of the diff_rigid_body package."""
    import rospkg
    return os.path.join(rospkg.RosPack().get_path('diff_rigid_body'), 'rviz', 'demo.rviz')


# ---------------------------------------------------------------------------- images
STATUS_BAR_ROWS = 32  # [px] see without_status_bar()


def grab(path):
    """Screenshots the whole X display ($DISPLAY) into ``path`` (PNG by extension)."""
    # -strip and no date chunks: the same picture gives the same file.
    subprocess.run(['import', '-silent', '-window', 'root', '-strip', '-define', 'png:exclude-chunks=date,time',
                    path], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return path


def read_rgb(path):
    """The image at ``path`` as (H, W, 3) uint8."""
    size = subprocess.run(['identify', '-format', '%w %h', path], check=True, stdout=subprocess.PIPE,
                          universal_newlines=True).stdout.split()
    width, height = int(size[0]), int(size[1])
    raw = subprocess.run(['stream', '-map', 'rgb', '-storage-type', 'char', path, '-'], check=True,
                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL).stdout
    return np.frombuffer(raw, dtype=np.uint8).reshape(height, width, 3)


def knot_mesh_mask(image):
    """Teal-ish pixels (the knot's mesh under rviz lighting)."""
    r, g, b = (image[..., k].astype(int) for k in range(3))
    return (g - r > 30) & (b - r > 30) & (np.abs(g - b) < 40)


def yellow_mask(image):
    """The knot's vertex markers."""
    r, g, b = (image[..., k].astype(int) for k in range(3))
    return (r > 180) & (g > 180) & (b < 90)


def magenta_mask(image):
    """The rock's vertex markers."""
    r, g, b = (image[..., k].astype(int) for k in range(3))
    return (r > 180) & (b > 180) & (g < 90)


def dilate(mask, radius):
    """Binary dilation by a (2 radius + 1)^2 square (box filter on an integral image)."""
    padded = np.pad(mask.astype(np.int32), radius + 1)
    integral = padded.cumsum(0).cumsum(1)
    d = 2 * radius + 1
    box = integral[d:, d:] - integral[:-d, d:] - integral[d:, :-d] + integral[:-d, :-d]
    return box[:mask.shape[0], :mask.shape[1]] > 0


def bounding_box(mask, margin=0):
    """(row0, row1, col0, col1) of the mask's pixels grown by ``margin``, or None."""
    rows, cols = np.nonzero(mask)
    if rows.size == 0:
        return None
    h, w = mask.shape
    return (max(rows.min() - margin, 0), min(rows.max() + margin + 1, h), max(cols.min() - margin, 0),
            min(cols.max() + margin + 1, w))


def box_mask(shape, box):
    mask = np.zeros(shape, dtype=bool)
    if box is not None:
        mask[box[0]:box[1], box[2]:box[3]] = True
    return mask


def centroid(mask):
    rows, cols = np.nonzero(mask)
    return np.array([rows.mean(), cols.mean()]) if rows.size else np.array([np.nan, np.nan])


def scene_counts(image):
    """Pixel counts of the knot mesh, knot markers and rock markers."""
    return {'knot mesh': int(knot_mesh_mask(image).sum()), 'knot markers': int(yellow_mask(image).sum()),
            'rock markers': int(magenta_mask(image).sum())}


def without_status_bar(image):
    """The screen without its bottom STATUS_BAR_ROWS rows: rviz's status bar
    (at the bottom of the 1280x800 window of rviz/demo.rviz) has an fps
    counter that changes by itself."""
    return image[:-STATUS_BAR_ROWS]


def wait_for_frame(directory, name, ready, timeout=90.0, period=1.0, stable_frames=2, rviz=None):
    """Screenshots every ``period`` s until ``ready(image)`` holds for
    ``stable_frames`` identical frames in a row; returns (path, image), the
    image :func:`without_status_bar`. Raises RuntimeError (naming the last
    counts) after ``timeout`` s. ``rviz`` (an :class:`Rviz`) is started again
    if it died meanwhile."""
    deadline = time.time() + timeout
    previous = None
    same = 0
    path = os.path.join(directory, name)
    while True:
        if rviz is not None:
            rviz.restart_if_dead()
        grab(path)
        image = without_status_bar(read_rgb(path))
        if ready(image):
            same = same + 1 if previous is not None and np.array_equal(image, previous) else 1
            if same >= stable_frames:
                return path, image
        else:
            same = 0
        previous = image
        if time.time() > deadline:
            raise RuntimeError('rviz did not show the expected scene within %g s (last frame %s: %s)' % (
                timeout, path, scene_counts(image)))
        time.sleep(period)


def scene_visible(image, minimum=200):
    """The knot mesh and both bodies' markers are on screen."""
    return all(count >= minimum for count in scene_counts(image).values())


# ---------------------------------------------------------------------------- processes
def software_gl_environment():
    env = dict(os.environ)
    env['LIBGL_ALWAYS_SOFTWARE'] = '1'
    return env


class Rviz(object):
    """rviz on $DISPLAY in its own process group, started again by :meth:`restart_if_dead` when it
    has died: rviz 1.14 with software OpenGL now and then aborts while it starts ("free(): invalid
    next size"), before it shows anything; a second start is the fix a user would apply."""

    def __init__(self, argv, log=None, starts=3):
        self.argv, self.log, self.starts_left = argv, log, starts
        self.process = None
        self.restart_if_dead()

    def restart_if_dead(self):
        if self.process is not None and self.process.poll() is None:
            return
        if self.starts_left == 0:
            raise RuntimeError('rviz exited with %s after every start (%s)' % (self.process.returncode, self.argv))
        if self.process is not None and self.log:
            self.log.write('\n[rviz_capture] rviz exited with %s; starting it again\n' % self.process.returncode)
            self.log.flush()
        self.starts_left -= 1
        self.process = subprocess.Popen(self.argv, env=software_gl_environment(), stdout=self.log or subprocess.DEVNULL,
                                        stderr=subprocess.STDOUT, start_new_session=True)


def start_rviz(config=None, log=None, fixed_frame=None):
    """:class:`Rviz` with ``config`` (default: rviz/demo.rviz), in ``fixed_frame`` (default: the config's)."""
    frame = ['-f', fixed_frame] if fixed_frame else []
    return Rviz(['rviz', '-d', config or demo_rviz_config()] + frame + ['__name:=rviz_capture'], log)


def stop(process, timeout=15.0):
    """SIGINT to the process group (of a Popen or an :class:`Rviz`), then SIGKILL."""
    process = getattr(process, 'process', process)
    if process is None or process.poll() is not None:
        return
    try:
        os.killpg(process.pid, signal.SIGINT)
        process.wait(timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
    except ProcessLookupError:
        pass


# ---------------------------------------------------------------------------- scripts/rviz_screenshot
def main(argv=None):
    parser = argparse.ArgumentParser(description='Screenshots the demo scene in rviz (run under xvfb-run).')
    parser.add_argument('output', help='PNG file to write')
    parser.add_argument('--port', type=int, required=True, help='ROS master port for roslaunch')
    parser.add_argument('--jacobian-column', type=int, default=-1, help='also draw dp/dq_j (0..5)')
    parser.add_argument('--timeout', type=float, default=120.0, help='[s] to wait for the scene')
    args = parser.parse_args(argv)
    if 'DISPLAY' not in os.environ:
        parser.error('no $DISPLAY: run under xvfb-run -a -s "-screen 0 1280x800x24"')

    log_path = os.path.join(os.environ.get('ROS_LOG_DIR', tempfile.gettempdir()), 'rviz_screenshot.log')
    with open(log_path, 'w') as log:
        launch = subprocess.Popen(
            ['roslaunch', '--port', str(args.port), 'diff_rigid_body', 'demo.launch', 'client:=false', 'rviz:=true',
             'jacobian_column:=%d' % args.jacobian_column], env=software_gl_environment(), stdout=log,
            stderr=subprocess.STDOUT, start_new_session=True)
        try:
            with tempfile.TemporaryDirectory() as directory:
                _, image = wait_for_frame(directory, 'frame.png', scene_visible, timeout=args.timeout)
                os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
                shutil.copyfile(os.path.join(directory, 'frame.png'), args.output)
            print('%s: pixels of %s' % (args.output, ', '.join('%s %d' % item for item in scene_counts(image).items())))
            return 0
        except RuntimeError as e:
            print('rviz_screenshot: %s (roslaunch log: %s)' % (e, log_path), file=sys.stderr)
            return 1
        finally:
            stop(launch)


if __name__ == '__main__':
    sys.exit(main())
