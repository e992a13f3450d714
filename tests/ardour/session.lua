-- An automated Ardour session with Ressort, exported headlessly (run by tests/ardour/export.sh
-- with Debian's `ardour7-lua`, Ardour 7.3).
--
--   ardour7-lua session.lua build  <session-dir> <name> <out-dir> <preset-uuid>
--       Makes a 48 kHz session: one MIDI track with Ressort (VST3) as its instrument, a MIDI
--       region (C4, then a C-E-G chord), and Stiffness automation in Play: ×1 until 1 s, a
--       ramp to ×2 at 3 s. Saves it, then exports 0 … 5 s in this process: build_1, build_2
--       (the plugin keeps running between them), build_3 (after a deactivation and an
--       activation) and noauto (the automation off, Stiffness held at ×1; not saved).
--   ardour7-lua session.lua export <session-dir> <name> <out-dir> <preset-uuid> <tag> <count>
--       Loads the saved session and exports it <count> times: <tag>_1.wav, <tag>_2.wav, …
--
-- What Ardour 7.3's Lua lacks, and the way round it:
-- * No call makes a MIDI region: bouncing the empty track without processing does
--   (`bounce_range` with the track's first processor as the end point; a nil processor
--   crashes the binding).
-- * No call sets the session range, which `ardour7-export` exports: adding the region inside
--   an undo transaction named "insert region" makes Ardour set it, as its editor does.
-- * No call scans plugins: export.sh runs `ardour-vst3-scanner` into the cache first.

local SR = 48000
local PLUGIN = "Ressort"
local EXPORT_SECONDS = 5
-- Stiffness's plain value is log2 of its factor: 0 is ×1, 1 is ×2.
local STIFF_FROM, STIFF_TO = 0, 1

local function log (...)
	local t = {}
	for _, v in ipairs ({...}) do t[#t + 1] = tostring (v) end
	print ("[ressort] " .. table.concat (t, " "))
end

local function die (msg)
	print ("[ressort] ERROR: " .. msg)
	pcall (close_session)
	os.exit (1)
end

local function find_plugin ()
	for t in Session:get_tracks ():iter () do
		local i = 0
		while true do
			local proc = t:nth_plugin (i)
			if proc:isnil () then break end
			local pi = proc:to_insert ()
			if not pi:isnil () and pi:plugin (0):name () == PLUGIN then
				return proc, pi:plugin (0)
			end
			i = i + 1
		end
	end
	die ("no " .. PLUGIN .. " insert in the session")
end

-- The Stiffness control: its index for `plugin_automation`, and its automation control.
local function stiffness (proc, plug)
	local n = 0
	while true do
		local id, r = plug:nth_parameter (n, true)
		if not r[2] then break end
		if plug:parameter_is_input (id) and plug:parameter_label (id) == "Stiffness" then
			local ac = proc:to_automatable ():automation_control (
				Evoral.Parameter (ARDOUR.AutomationType.PluginAutomation, 0, id), false)
			if ac:isnil () then die ("no automation control for Stiffness") end
			return n, ac
		end
		n = n + 1
	end
	die ("no Stiffness parameter")
end

local function export (outdir, name, uuid)
	local e = Session:simple_export ()
	if not e:set_preset (uuid) then die ("no export preset " .. uuid) end
	e:set_folder (outdir)
	e:set_name (name)
	e:set_range (0, EXPORT_SECONDS * SR)
	if not e:check_outputs () then die ("the master bus has no outputs") end
	if not e:run_export () then die ("export " .. name .. " failed") end
	log ("exported", name, "master latency", Session:master_out ():playback_latency (false))
	collectgarbage ()
end

local function build (dir, name, outdir, uuid)
	if not create_session (dir, name, SR) then die ("create_session failed") end
	local pinfo = ARDOUR.LuaAPI.new_plugin_info (PLUGIN, ARDOUR.PluginType.VST3)
	if pinfo:isnil () then die ("Ressort is not in Ardour's plugin cache") end
	-- Strict I/O: the track's outputs are the plugin's main pair, not its auxiliary ones too.
	local tracks = Session:new_midi_track (
		ARDOUR.ChanCount (ARDOUR.DataType ("midi"), 1),
		ARDOUR.ChanCount (ARDOUR.DataType ("audio"), 2),
		true, pinfo, nil, nil, 1, "Ressort", ARDOUR.PresentationInfo.max_order,
		ARDOUR.TrackMode.Normal, true, false)
	if tracks:size () ~= 1 then die ("new_midi_track failed") end
	local track = tracks:front ()
	local proc, plug = find_plugin ()

	local region = track:bounce_range (0, EXPORT_SECONDS * SR, ARDOUR.InterThreadInfo (),
	                                   track:nth_processor (0), false, "notes")
	if region:isnil () then die ("no MIDI region") end
	local model = region:to_midiregion ():model ()
	local cmd = model:new_note_diff_command ("add notes")
	-- 120 bpm: a beat is 0.5 s. C4 at 0.25 s for 1.5 s, then C-E-G at 2 s for 2 s.
	local function beats (x) return Temporal.Beats.from_double (x) end
	cmd:add (ARDOUR.LuaAPI.new_noteptr (0, beats (0.5), beats (3.0), 60, 100))
	for _, key in ipairs ({60, 64, 67}) do
		cmd:add (ARDOUR.LuaAPI.new_noteptr (0, beats (4.0), beats (4.0), key, 90))
	end
	model:apply_command (Session, cmd)
	local playlist = track:playlist ()
	Session:begin_reversible_command ("insert region")
	playlist:to_stateful ():clear_changes ()
	playlist:add_region (region, Temporal.timepos_t (0), 1, false)
	Session:add_stateful_diff_command (playlist:to_statefuldestructible ())
	Session:commit_reversible_command (nil)

	local n, ac = stiffness (proc, plug)
	local _, list = ARDOUR.LuaAPI.plugin_automation (proc, n)
	list:clear_list ()
	list:add (Temporal.timepos_t (0), STIFF_FROM, false, false)
	list:add (Temporal.timepos_t (1 * SR), STIFF_FROM, false, false)
	list:add (Temporal.timepos_t (3 * SR), STIFF_TO, false, false)
	ac:set_automation_state (ARDOUR.AutoState.Play)
	log ("Stiffness automation:", list:size (), "points, at 2 s", list:eval (Temporal.timepos_t (2 * SR)))

	Session:save_state ("", false, false, false, false, false)
	export (outdir, "build_1", uuid)
	export (outdir, "build_2", uuid)
	proc:deactivate ()
	proc:activate ()
	export (outdir, "build_3", uuid)

	ac:set_automation_state (ARDOUR.AutoState.Off)
	ac:set_value (STIFF_FROM, PBD.GroupControlDisposition.NoGroup)
	export (outdir, "noauto", uuid)
	close_session ()
end

local function reload (dir, name, outdir, uuid, tag, count)
	if not load_session (dir, name) then die ("load_session failed") end
	local proc, plug = find_plugin ()
	local _, ac = stiffness (proc, plug)
	if ac:automation_state () ~= ARDOUR.AutoState.Play then
		die ("the saved Stiffness automation is not in Play")
	end
	for i = 1, count do
		export (outdir, tag .. "_" .. i, uuid)
	end
	close_session ()
end

-- Ardour adds the port resampler's latency (16 samples) to the master's playback latency only
-- once its outputs count as connected, which races with the latency computation as the engine
-- starts: the master's latency came out 256 or 272 samples from run to run, moving the cycle
-- boundaries where Ardour hands VST3 automation to the plugin. Without the resampler (it is
-- for vari-speed) the latency is always 256. export.sh also writes it to the config file,
-- which ardour7-export reads. Set before the engine starts.
ARDOUR.config ():set_port_resampler_quality (0)

local mode = arg[1]
if mode == "build" then
	build (arg[2], arg[3], arg[4], arg[5])
elseif mode == "export" then
	reload (arg[2], arg[3], arg[4], arg[5], arg[6], tonumber (arg[7]))
else
	print ("usage: ardour7-lua session.lua build|export ...")
	os.exit (2)
end
