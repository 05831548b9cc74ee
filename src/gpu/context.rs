//! A headless wgpu device: Vulkan first (a real GPU or lavapipe), OpenGL (llvmpipe) as fallback,
//! with the error handling every lodkit call goes through: error scopes around the call, a handler
//! that records errors raised outside them, and device-loss tracking.
//!
//! On wgpu's GL backend every GL call takes one context lock, and a thread that waits more than
//! 6 s for it panics ("Could not lock adapter context"). A GL driver can hold that lock for
//! seconds in one call: llvmpipe links a large shader in several seconds when its shader cache is
//! cold, and a fence wait holds it while the GPU works. So on GL a [`GpuContext`] also has a gate:
//! every lodkit call passes through it one at a time, and waits there without a time limit
//! instead of in wgpu's lock. Engine code that uses the same device from several threads runs its
//! own device work through [`GpuContext::exclusive`].

use std::borrow::Cow;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::{Arc, Mutex, PoisonError};

use super::{GpuCapabilities, GpuError};
use crate::shaders::Composed;

/// Most errors the uncaptured-error handler keeps (it still counts the rest).
const RECORDED_ERRORS: usize = 16;

/// Options for [`GpuContext::new_headless`].
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// Backends to try, in order. Empty: `LODKIT_BACKEND` if set, else Vulkan then GL.
    pub backends: Vec<wgpu::Backends>,
    /// Optional features to enable when the adapter has them (others are silently left out).
    pub optional_features: wgpu::Features,
    /// Limits to ask the device for; `None`: everything the adapter offers. Lower limits make
    /// a device that behaves as a smaller GPU would (tests of what lodkit does at the limits).
    pub limits: Option<wgpu::Limits>,
}

/// Options for [`GpuContext::from_parts_with`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GpuContextDescriptor {
    /// Whose handlers the device keeps (default [`DeviceHandlers::Keep`]: the engine's).
    pub handlers: DeviceHandlers,
}

/// Whose uncaptured-error handler and device-lost callback a device has:
/// [`GpuContextDescriptor::handlers`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DeviceHandlers {
    /// The engine's, left as they are (the default over an engine's device). Errors outside
    /// lodkit's calls and the device's loss reach them; lodkit reports neither as
    /// [`GpuError::Uncaptured`] or a recorded loss.
    #[default]
    Keep,
    /// lodkit's (what [`GpuContext::new_headless`] installs): an uncaptured-error handler that
    /// records errors instead of panicking, reported by the next lodkit call as
    /// [`GpuError::Uncaptured`], and a device-lost callback whose loss every later call reports
    /// as [`GpuError::DeviceLost`]. They replace any the engine set.
    Install,
}

/// A device and queue with the adapter they came from, and what lodkit learned about the device:
/// errors wgpu raised outside lodkit's calls, and whether the device is lost.
#[derive(Debug)]
pub struct GpuContext {
    /// The wgpu instance.
    pub instance: wgpu::Instance,
    /// The adapter in use.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    state: Arc<DeviceState>,
    /// On GL: taken by every lodkit call, so that two never meet in wgpu's timed context lock.
    gate: Option<Mutex<()>>,
    /// What the device really can do (wgpu's answer, corrected on downlevel GL contexts).
    capabilities: GpuCapabilities,
}

/// What the device callbacks recorded.
#[derive(Debug, Default)]
struct DeviceState {
    /// (reason, message) once the device is lost.
    lost: Mutex<Option<(String, String)>>,
    /// Errors no scope caught: how many, and the first [`RECORDED_ERRORS`] descriptions.
    uncaptured: Mutex<(usize, Vec<String>)>,
}

impl DeviceState {
    fn lost(&self) -> Option<(String, String)> {
        self.lost
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }

    fn record_lost(&self, reason: String, message: String) {
        let mut lost = self.lost.lock().unwrap_or_else(PoisonError::into_inner);
        lost.get_or_insert((reason, message));
    }

    fn record_error(&self, description: String) {
        let mut recorded = self
            .uncaptured
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        recorded.0 += 1;
        if recorded.1.len() < RECORDED_ERRORS {
            recorded.1.push(description);
        }
    }

    fn take_errors(&self) -> (usize, Vec<String>) {
        std::mem::take(
            &mut *self
                .uncaptured
                .lock()
                .unwrap_or_else(PoisonError::into_inner),
        )
    }
}

impl GpuContext {
    /// Creates a device without a window, blocking until it is ready, with every limit the
    /// adapter has. On a GL context that claims compute shaders its shading language lacks
    /// (GL 3.3 with `GL_ARB_compute_shader`, see [`GpuCapabilities`]) the instance leaves out
    /// wgpu's indirect-call validation, whose compute pipelines would lose the device; lodkit's
    /// passes then refuse what the context cannot do ([`GpuError::MissingCapability`]).
    pub fn new_headless(options: &GpuOptions) -> Result<Self, GpuError> {
        let backends = if options.backends.is_empty() {
            match std::env::var("LODKIT_BACKEND") {
                Ok(name) => vec![parse_backend(&name)?],
                Err(_) => vec![wgpu::Backends::VULKAN, wgpu::Backends::GL],
            }
        } else {
            options.backends.clone()
        };
        for &backends in &backends {
            let instance_for = |flags: wgpu::InstanceFlags| {
                let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
                desc.backends = backends;
                desc.flags = flags;
                let instance = wgpu::Instance::new(desc);
                let request = wgpu::RequestAdapterOptions {
                    power_preference: wgpu::PowerPreference::HighPerformance,
                    ..Default::default()
                };
                let adapter = pollster::block_on(instance.request_adapter(&request)).ok()?;
                Some((instance, adapter))
            };
            let flags = wgpu::InstanceDescriptor::new_without_display_handle_from_env().flags;
            let Some((mut instance, mut adapter)) = instance_for(flags) else {
                continue;
            };
            // wgpu-core builds compute pipelines for its indirect-call validation when it creates
            // a device on an adapter that claims compute shaders, and reports their failure as a
            // lost device ("Parent device is lost"): a GL 3.3 context whose driver lists
            // GL_ARB_compute_shader (NVIDIA's EGL, Mesa with a version override) claims them
            // without GLSL 4.30. There the instance goes without that validation.
            let indirect = wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL;
            let claims_compute = adapter
                .get_downlevel_capabilities()
                .flags
                .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS);
            if flags.contains(indirect)
                && claims_compute
                && !GpuCapabilities::of_adapter(&adapter).compute_shaders()
            {
                let Some(found) = instance_for(flags - indirect) else {
                    continue;
                };
                (instance, adapter) = found;
            }
            let required_features = adapter.features() & options.optional_features;
            let device_desc = wgpu::DeviceDescriptor {
                label: Some("lodkit headless device"),
                required_features,
                required_limits: options.limits.clone().unwrap_or_else(|| adapter.limits()),
                ..Default::default()
            };
            let (device, queue) = pollster::block_on(adapter.request_device(&device_desc))
                .map_err(|source| GpuError::RequestDevice {
                    adapter: adapter.get_info().name,
                    source,
                })?;
            let descriptor = GpuContextDescriptor {
                handlers: DeviceHandlers::Install,
            };
            return Ok(Self::from_parts_with(
                instance,
                adapter,
                device,
                queue,
                &descriptor,
            ));
        }
        let tried = backends
            .iter()
            .map(|b| format!("{b:?}"))
            .collect::<Vec<_>>()
            .join(", ");
        Err(GpuError::NoAdapter { tried })
    }

    /// A context over a device the engine already has, leaving the engine's uncaptured-error
    /// handler and device-lost callback in place: lodkit's calls catch their own errors with
    /// error scopes; errors outside them and the device's loss go to the engine's handlers, and
    /// lodkit names a lost device when a call's work fails on it. Same as
    /// [`from_parts_with`](Self::from_parts_with) with the default [`GpuContextDescriptor`].
    pub fn from_parts(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> Self {
        Self::from_parts_with(
            instance,
            adapter,
            device,
            queue,
            &GpuContextDescriptor::default(),
        )
    }

    /// A context over a device the engine already has, with the device handlers
    /// `descriptor` asks for ([`DeviceHandlers`]).
    pub fn from_parts_with(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
        descriptor: &GpuContextDescriptor,
    ) -> Self {
        let state = Arc::new(DeviceState::default());
        if descriptor.handlers == DeviceHandlers::Install {
            let recorder = Arc::clone(&state);
            device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
                recorder.record_error(error.to_string());
            }));
            let recorder = Arc::clone(&state);
            device.set_device_lost_callback(move |reason, message| {
                let message = if message.is_empty() {
                    "no message".into()
                } else {
                    message
                };
                recorder.record_lost(format!("{reason:?}"), message);
            });
        }
        let gl = adapter.get_info().backend == wgpu::Backend::Gl;
        let capabilities = GpuCapabilities::of_adapter(&adapter);
        Self {
            instance,
            adapter,
            device,
            queue,
            state,
            gate: gl.then(|| Mutex::new(())),
            capabilities,
        }
    }

    /// What the device really can do: wgpu's downlevel flags, less what the context's shading
    /// language cannot do on a downlevel GL context, and whether a pipeline may bind more than
    /// one texture and one uniform buffer (see [`GpuCapabilities`]). lodkit's capability checks
    /// read this, never the adapter's own flags.
    pub fn capabilities(&self) -> &GpuCapabilities {
        &self.capabilities
    }

    /// Runs `f` (work on this context's device) while no lodkit call runs on it. On wgpu's GL
    /// backend lodkit's calls pass one at a time through a gate, and this takes the same gate:
    /// an engine that uses the device from several threads besides lodkit's calls runs its
    /// device work through it, so that no thread waits in wgpu's GL context lock, which panics
    /// after 6 s (a cold shader link can hold it longer). On other backends it just runs `f`.
    /// Calls nest: lodkit calls made inside `f` do not wait for the gate again.
    pub fn exclusive<T>(&self, f: impl FnOnce() -> T) -> T {
        let _gate = self.gate();
        f()
    }

    /// This thread's hold of the GL gate; `None` off GL or when this thread holds it already.
    fn gate(&self) -> Option<GateHold<'_>> {
        let gate = self.gate.as_ref()?;
        if GATE_HELD.with(|held| held.replace(true)) {
            return None;
        }
        let guard = gate.lock().unwrap_or_else(PoisonError::into_inner);
        Some(GateHold(guard))
    }

    /// `Ok` while the device is alive and no error was recorded outside lodkit's calls;
    /// otherwise [`GpuError::DeviceLost`], or [`GpuError::Uncaptured`] with the recorded errors
    /// (which it clears). `call` names the caller in the error. It polls the device first (no
    /// wait): wgpu notices a lost or destroyed device, and calls the lost callback, when it is
    /// polled or a submission is made. An engine that wants a lost device named promptly calls it
    /// once per frame; lodkit's recordings do not poll (see [`recording`](Self::recording)).
    pub fn check(&self, call: &'static str) -> Result<(), GpuError> {
        let _gate = self.gate();
        // A device the driver lost makes wgpu 30's poll panic instead of returning an error;
        // that panic is caught here and reported as a lost device.
        if self.poll(wgpu::PollType::Poll) == Polled::ContextTimeout {
            return Err(GpuError::ContextTimeout { call });
        }
        self.recorded(call)
    }

    /// What the device callbacks recorded, without polling: [`check`](Self::check) less the
    /// poll.
    fn recorded(&self, call: &'static str) -> Result<(), GpuError> {
        if let Some((reason, message)) = self.state.lost() {
            return Err(GpuError::DeviceLost {
                call,
                reason,
                message,
            });
        }
        let (count, errors) = self.state.take_errors();
        match errors.into_iter().next() {
            Some(first) => Err(GpuError::Uncaptured { call, count, first }),
            None => Ok(()),
        }
    }

    /// Runs `f` (device work of lodkit call `call`: creating or resizing resources, reading
    /// back) inside out-of-memory, validation and internal error scopes: the first error wgpu
    /// raised during `f` comes back as this call's error instead of reaching the
    /// uncaptured-error handler. Before `f` it [`check`](Self::check)s the device (one poll, no
    /// wait: with lodkit's handlers, [`DeviceHandlers::Install`], a device destroyed or lost
    /// since is named here, as work on it would otherwise succeed silently); after, what the
    /// device callbacks recorded is this call's error. Over an engine's own handlers
    /// ([`DeviceHandlers::Keep`]) the loss goes to the engine's callback instead.
    /// Per-frame recordings go through [`recording`](Self::recording), which does not poll.
    ///
    /// Inside another guarded call on the same thread it only runs `f`: the outermost call, the
    /// one the engine made, names the error.
    pub fn guarded<T>(
        &self,
        call: &'static str,
        f: impl FnOnce() -> Result<T, GpuError>,
    ) -> Result<T, GpuError> {
        self.scoped(call, true, f)
    }

    /// [`guarded`](Self::guarded) for a recording into the engine's encoder, at the cost of the
    /// error scopes and nothing more: no device poll and no wait. On native wgpu a scope's
    /// result is ready when it is popped and is read there (a pending one, the browser's WebGPU,
    /// is waited for). With lodkit's handlers ([`DeviceHandlers::Install`]) a lost device is
    /// noticed when wgpu notices it, at the engine's next submission or poll (or
    /// [`check`](Self::check)), and named by the next lodkit call. An
    /// application's own passes can record through it to get lodkit's error handling and its
    /// host cost (the demo's baselines do, to be timed fairly against lodkit's passes).
    pub fn recording<T>(
        &self,
        call: &'static str,
        f: impl FnOnce() -> Result<T, GpuError>,
    ) -> Result<T, GpuError> {
        self.scoped(call, false, f)
    }

    /// [`guarded`](Self::guarded), polling first or not.
    fn scoped<T>(
        &self,
        call: &'static str,
        poll: bool,
        f: impl FnOnce() -> Result<T, GpuError>,
    ) -> Result<T, GpuError> {
        let Some(_outermost) = Outermost::enter() else {
            return f();
        };
        let _gate = self.gate();
        if poll {
            self.check(call)?;
        } else {
            self.recorded(call)?;
        }
        let out_of_memory = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let internal = self.device.push_error_scope(wgpu::ErrorFilter::Internal);
        let value = f();
        let popped = [internal.pop(), validation.pop(), out_of_memory.pop()];
        let caught = popped.into_iter().find_map(ready_or_wait);
        let value = value?;
        self.recorded(call)?;
        match caught {
            Some(error) => Err(GpuError::from_wgpu(call, error)),
            None => Ok(value),
        }
    }

    /// Polls the device. A panic inside wgpu's poll is caught: wgpu's GL backend panics when
    /// another thread held the GL context for more than 6 s, which loses nothing (this call
    /// timed out; the next may go through); any other panic is wgpu's answer to a driver-lost
    /// device and is recorded as one.
    fn poll(&self, poll_type: wgpu::PollType) -> Polled {
        let panic = match catch_unwind(AssertUnwindSafe(|| self.device.poll(poll_type))) {
            Ok(Err(wgpu::PollError::Timeout)) => return Polled::WaitTimedOut,
            Ok(_) => return Polled::Done,
            Err(panic) => panic,
        };
        let message = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        if message.contains(GL_LOCK_TIMEOUT) {
            return Polled::ContextTimeout;
        }
        self.state.record_lost(
            "Unknown".into(),
            format!("wgpu panicked while polling the device: {message}"),
        );
        Polled::Lost
    }

    /// What the device can do with `format`: the adapter's own answer when the device has
    /// `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES`, the guaranteed WebGPU set otherwise.
    pub fn format_features(&self, format: wgpu::TextureFormat) -> wgpu::TextureFormatFeatures {
        let features = self.device.features();
        if features.contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES) {
            self.adapter.get_texture_format_features(format)
        } else {
            format.guaranteed_format_features(features)
        }
    }

    /// One line about the adapter: name, backend, device type, driver.
    pub fn adapter_summary(&self) -> String {
        let info = self.adapter.get_info();
        format!(
            "{} ({:?}, {:?}, driver: {} {})",
            info.name, info.backend, info.device_type, info.driver, info.driver_info
        )
    }

    /// A shader module from a composed lodkit module (no re-parsing: naga IR goes straight in).
    /// [`GpuError::MissingCapability`] when a pipeline built from it could not run correctly on
    /// this device ([`GpuCapabilities::check_module`]): compute or storage buffers the device
    /// lacks, or more textures or uniform buffers than a downlevel GL context can bind.
    pub fn shader_module(
        &self,
        label: &str,
        composed: &Composed,
    ) -> Result<wgpu::ShaderModule, GpuError> {
        const CALL: &str = "GpuContext::shader_module";
        self.capabilities
            .check_module(CALL, &composed.module, &composed.info)?;
        self.guarded(CALL, || {
            Ok(self
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(label),
                    source: wgpu::ShaderSource::Naga(Cow::Owned(composed.module.clone())),
                }))
        })
    }

    /// The shader module of lodkit's pass `shader_lib/passes/<name>.wgsl`, composed with the
    /// boolean shader defs `defs` switched on.
    pub fn pass_module(&self, name: &str, defs: &[&str]) -> Result<wgpu::ShaderModule, GpuError> {
        let composed = crate::shaders::compose_pass(name, defs)?;
        self.guarded("GpuContext::pass_module", || {
            self.shader_module(name, &composed)
        })
    }

    /// Blocks until the GPU has finished all submitted work. A lost device is an error, not a
    /// hang or a panic.
    pub fn wait_idle(&self) -> Result<(), GpuError> {
        const CALL: &str = "GpuContext::wait_idle";
        let _gate = self.gate();
        self.check(CALL)?;
        // wgpu's GL backend waits at most about 4.3 s per fence wait and then reports a
        // timeout, though the work goes on: wait again until it is done.
        loop {
            match self.poll(wgpu::PollType::wait_indefinitely()) {
                Polled::WaitTimedOut => continue,
                Polled::ContextTimeout => return Err(GpuError::ContextTimeout { call: CALL }),
                Polled::Done | Polled::Lost => break,
            }
        }
        self.check(CALL)
    }
}

/// A future's output: at once where it is ready (native wgpu's error scopes are), else waited
/// for.
fn ready_or_wait<F: std::future::Future>(future: F) -> F::Output {
    let mut future = std::pin::pin!(future);
    let mut context = std::task::Context::from_waker(std::task::Waker::noop());
    match future.as_mut().poll(&mut context) {
        std::task::Poll::Ready(output) => output,
        std::task::Poll::Pending => pollster::block_on(future),
    }
}

/// How a poll went.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Polled {
    Done,
    /// A wait ended before the work it waited for.
    WaitTimedOut,
    /// wgpu's GL backend gave up waiting for its context lock.
    ContextTimeout,
    /// wgpu panicked otherwise: the device is lost.
    Lost,
}

/// What wgpu-hal's GL backend panics with when it waited too long for its context lock.
const GL_LOCK_TIMEOUT: &str = "Could not lock adapter context";

/// This thread's hold of a context's GL gate (see [`GpuContext::exclusive`]).
struct GateHold<'a>(#[allow(dead_code)] std::sync::MutexGuard<'a, ()>);

impl Drop for GateHold<'_> {
    fn drop(&mut self) {
        GATE_HELD.with(|held| held.set(false));
    }
}

thread_local! {
    /// Whether this thread is inside a guarded lodkit call.
    static GUARDED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Whether this thread holds a context's GL gate (one context's at a time: an engine with two
    /// GL contexts on one thread nests their gates by hand).
    static GATE_HELD: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Marks this thread as inside a guarded call until dropped (also when unwinding).
struct Outermost;

impl Outermost {
    /// `None` when the thread already is inside a guarded call.
    fn enter() -> Option<Self> {
        (!GUARDED.with(|g| g.replace(true))).then_some(Self)
    }
}

impl Drop for Outermost {
    fn drop(&mut self) {
        GUARDED.with(|g| g.set(false));
    }
}

fn parse_backend(name: &str) -> Result<wgpu::Backends, GpuError> {
    match name.to_ascii_lowercase().as_str() {
        "vulkan" | "vk" => Ok(wgpu::Backends::VULKAN),
        "gl" | "gles" | "opengl" => Ok(wgpu::Backends::GL),
        "metal" => Ok(wgpu::Backends::METAL),
        "dx12" => Ok(wgpu::Backends::DX12),
        _ => Err(GpuError::UnknownBackend(name.to_owned())),
    }
}
