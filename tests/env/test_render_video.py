"""Rendering of the v0 and v1 envs: rgb_array frames, Gymnasium's RecordVideo writing a video
file (it needs moviepy, in the ``rl`` extra), and the v1 picture showing the payload swing."""

import gymnasium as gym
import numpy as np
import pytest

import boom_env  # noqa: F401

pytest.importorskip("moviepy", reason="RecordVideo needs moviepy (the rl extra)")


@pytest.mark.parametrize("env_id", ["boom_env/TelescopicExtraction-v0",
                                    "boom_env/TelescopicExtraction-v1"])
def test_record_video_writes_a_video(env_id, tmp_path):
    from gymnasium.wrappers import RecordVideo
    env = gym.make(env_id, render_mode="rgb_array", t_max=0.5)
    env = RecordVideo(env, str(tmp_path), episode_trigger=lambda ep: True,
                      name_prefix="boom", disable_logger=True)
    env.reset(seed=0)
    frames = []
    for _ in range(10):
        _, _, term, trunc, _ = env.step(np.array([1.0], np.float32))
        frames.append(env.render())
        if term or trunc:
            break
    env.close()
    videos = list(tmp_path.glob("boom-episode-0.mp4"))
    assert len(videos) == 1 and videos[0].stat().st_size > 1000
    f = frames[-1]
    assert f.dtype == np.uint8 and f.ndim == 3 and f.shape[2] == 3
    assert not np.array_equal(frames[0], frames[-1])          # the picture moves


def test_v1_frame_shows_the_payload_swing():
    """The payload (a brown square on its rope below the tip) is drawn where the sway puts it:
    swung by 0.2 rad on the 5 m rope (sway drawn at true scale) its pixels' centre moves by the
    data-to-pixel image of l (sin 0.2, 1 - cos 0.2) = (0.99, 0.10) m, within 2 px."""
    from matplotlib.colors import to_rgb
    env = gym.make("boom_env/TelescopicExtraction-v1", render_mode="rgb_array",
                   render_sway_exaggeration=1.0).unwrapped
    brown = np.round(255 * np.array(to_rgb("tab:brown"))).astype(int)

    def centre(frame):
        mask = np.all(np.abs(frame.astype(int) - brown) <= 2, axis=2)
        ys, xs = np.nonzero(mask)
        assert xs.size > 20
        return np.array([xs.mean(), ys.mean()])
    env.reset(seed=0)
    c0 = centre(env.render())
    env.reset(seed=0, options={"sway": (0.2, 0.0)})
    c1 = centre(env.render())
    ax = env._fig["ax"]
    h = env._fig["fig"].canvas.get_width_height()[1]
    p0 = ax.transData.transform((0.0, 0.0))
    p1 = ax.transData.transform((5.0 * np.sin(0.2), 5.0 * (1.0 - np.cos(0.2))))
    expected = np.array([p1[0] - p0[0], -(p1[1] - p0[1])])      # image rows grow downwards
    assert h > 0
    assert np.allclose(c1 - c0, expected, atol=2.0)


def test_vector_env_renders_its_first_sub_env():
    v = gym.make_vec("boom_env/TelescopicExtraction-v1", num_envs=3, render_mode="rgb_array")
    v.reset(seed=0)
    frame = v.render()
    assert frame.dtype == np.uint8 and frame.shape[2] == 3
    v.close()
