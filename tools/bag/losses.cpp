#include "losses.hpp"

#include <algorithm>
#include <climits>
#include <cstdio>
#include <map>
#include <optional>

#include <dyad/cdr_decoder.hpp>

namespace dyad::bag {
namespace {

struct WriterState {
  WriterLosses losses;
  std::int64_t last_stamp = 0, first_stamp = 0;
  bool events = false;  // speaks only when something happens: silence is no loss
};

// Topics that carry events, not a stream: dyad/health, and these types (a live param's answer,
// the deliberator's model at start and at each swap, a person's answer after a release).
bool CarriesEvents(const std::string& topic, const std::string& type) {
  return topic == "dyad/health" || type == "dyad::msg::ParamChange" || type == "dyad::msg::ModelInfo" ||
         type == "dyad::msg::SelfReport";
}

const std::string* FieldValue(const std::vector<cdr::Field>& fields, const char* path) {
  for (const auto& f : fields)
    if (f.path == path) return &f.value;
  return nullptr;
}

std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f s", s);
  return text;
}

// One state sample of a driver: a stop begins at the first stopped sample and ends at the first
// one that is not.
void NoteArm(const std::string& topic, const std::string* stopped, std::int64_t t, std::vector<ArmStops>* arms) {
  if (stopped == nullptr) return;
  auto it = std::find_if(arms->begin(), arms->end(), [&](const ArmStops& a) { return a.topic == topic; });
  const bool now = *stopped == "true";
  if (it == arms->end()) {
    if (!now) return;
    arms->push_back({topic, {}, false});
    it = arms->end() - 1;
  }
  if (now && !it->stopped_now) it->stops.push_back({t, t, true});
  if (now) it->stops.back().to_ns = t;
  if (!now && it->stopped_now) {
    it->stops.back().to_ns = t;
    it->stops.back().until_end = false;
  }
  it->stopped_now = now;
}

}  // namespace

StatusOr<Losses> FindLosses(const mcap::Reader& reader) {
  std::map<mcap::ChannelId, std::optional<cdr::Schema>> schemas;
  for (const auto& [id, channel] : reader.channels()) {
    auto s = reader.schemas().find(channel.schema_id);
    if (s == reader.schemas().end() || s->second.encoding != "omgidl") continue;
    auto parsed = cdr::Schema::Parse(s->second.data);
    if (parsed.ok() && parsed->HasType(s->second.name)) schemas[id] = *parsed;
  }
  std::map<std::pair<std::string, std::string>, WriterState> writers;
  Losses out;
  std::vector<cdr::Field> fields;
  std::int64_t end_ns = 0, start_ns = INT64_MAX;
  mcap::ReadOptions options;
  options.skip_damaged = true;
  Status st = reader.ReadMessages(options, [&](const mcap::MessageView& m) {
    auto it = schemas.find(m.channel->id);
    if (it == schemas.end() || !it->second) return true;
    const std::string& type = reader.schemas().at(m.channel->schema_id).name;
    if (!cdr::Decode(*it->second, type, m.data.data(), m.data.size(), &fields).ok()) return true;
    const std::string* source = FieldValue(fields, "header.source");
    const std::string* seq = FieldValue(fields, "header.sequence_number");
    const std::string* stamp = FieldValue(fields, "header.stamp_ns");
    if (source == nullptr || seq == nullptr || stamp == nullptr) return true;
    const std::uint64_t n = std::stoull(*seq);
    const std::int64_t t = std::stoll(*stamp);
    end_ns = std::max(end_ns, t);
    start_ns = std::min(start_ns, t);
    if (type == "dyad::msg::CartesianState") NoteArm(m.channel->topic, FieldValue(fields, "stopped"), t, &out.arms);
    if (m.channel->topic == "dyad/health") {
      const auto get = [&](const char* p) { const std::string* v = FieldValue(fields, p); return v ? *v : std::string(); };
      std::string line = get("process_name") + " " + get("endpoint");
      if (!get("topic").empty()) line += " of '" + get("topic") + "'";
      line += ": " + get("action") + " (matched " + get("matched") + " of " + get("expected") + ", for " +
              Seconds(std::stod(get("starved_s").empty() ? "0" : get("starved_s"))) + ", renewal " + get("renewals") + ")";
      out.health.emplace_back(t, line);
    }
    auto [w, fresh] = writers.try_emplace({m.channel->topic, *source});
    WriterState& s = w->second;
    if (fresh) {
      s.losses.topic = m.channel->topic;
      s.losses.writer = *source;
      s.losses.first = s.losses.last = n;
      s.first_stamp = t;
      s.events = CarriesEvents(m.channel->topic, type);
    } else if (n > s.losses.last + 1) {
      s.losses.gaps.push_back({n - s.losses.last - 1, s.last_stamp, t});
    }
    if (fresh || n > s.losses.last) {
      s.losses.last = n;
      s.last_stamp = t;
    }
    ++s.losses.samples;
    return true;
  });
  if (!st.ok()) return st;
  out.start_ns = start_ns == INT64_MAX ? 0 : start_ns;
  for (auto& [key, s] : writers) {
    const double span = (s.last_stamp - s.first_stamp) * 1e-9;
    const double usual = s.losses.samples > 1 ? span / static_cast<double>(s.losses.samples - 1) : 0;
    const double silent = (end_ns - s.last_stamp) * 1e-9;
    if (silent > 2 && silent > 10 * usual && !s.events) s.losses.silent_at_end_s = silent;
    out.writers.push_back(std::move(s.losses));
  }
  return out;
}

std::string FormatLosses(const Losses& losses) {
  std::string out = "losses:      per writer, from the gaps in its sequence numbers (times from the first stamp)\n";
  bool any = false;
  for (const auto& w : losses.writers) {
    if (w.gaps.empty() && w.silent_at_end_s == 0 && w.first == 1) continue;
    any = true;
    std::uint64_t missing = 0;
    for (const auto& g : w.gaps) missing += g.missing;
    out += "  " + w.topic + "  " + w.writer + "  " + std::to_string(w.samples) + " samples, " + std::to_string(w.first) +
           ".." + std::to_string(w.last) + ": " + std::to_string(missing) + " missing";
    if (w.first > 1) out += " (recording joined at " + std::to_string(w.first) + ")";
    out += "\n";
    for (const auto& g : w.gaps) {
      char line[160];
      std::snprintf(line, sizeof(line), "    %llu lost from +%.1f s to +%.1f s\n", static_cast<unsigned long long>(g.missing),
                    (g.from_ns - losses.start_ns) * 1e-9, (g.to_ns - losses.start_ns) * 1e-9);
      out += line;
    }
    if (w.silent_at_end_s > 0)
      out += "    silent for the last " + Seconds(w.silent_at_end_s) + " of the recording\n";
  }
  if (!any) out += "  none: every writer's samples are contiguous to the end\n";
  for (const auto& a : losses.arms) {
    double total = 0;
    for (const auto& st : a.stops) total += (st.to_ns - st.from_ns) * 1e-9;
    out += "arm:         " + a.topic + ": stopped " + std::to_string(a.stops.size()) +
           (a.stops.size() == 1 ? " time, " : " times, ") + Seconds(total) +
           " (the driver could not move the arm; the mixer holds meanwhile)\n";
    for (const auto& st : a.stops)
      out += "  +" + Seconds((st.from_ns - losses.start_ns) * 1e-9) + "  for " + Seconds((st.to_ns - st.from_ns) * 1e-9) +
             (st.until_end ? ", still stopped at the end" : "") + "\n";
  }
  if (!losses.health.empty()) {
    out += "health:      " + std::to_string(losses.health.size()) + " event(s) on dyad/health\n";
    for (const auto& [t, what] : losses.health) out += "  +" + Seconds((t - losses.start_ns) * 1e-9) + "  " + what + "\n";
  }
  return out;
}

}  // namespace dyad::bag
