"""Cameras: discovery (sysfs), the Minoru and side-by-side sources, replay, calibration files
and the stereo calibration itself."""

# the submodules (imported on use: a package import stays cheap)
__all__ = ["calib_files", "calib_report", "calibration", "controls", "discovery", "live",
           "lr_check", "manifest", "minoru", "open", "replay", "sbs", "source", "stamps",
           "uvc_descriptors"]
