// Docs that tell the truth (issue 34): every name README.md and docs/*.md give in backticks — a
// file path, a function or type, a command-line option — must exist, so that a rename or a move
// that forgets a page fails a test instead of misleading the next reader. Each code span is
// classified (path, name of the code, option, `lodforge …` command line; anything else is prose,
// a value or a code fragment and is not checked) and looked up in what is really there: the
// files of the checkout, the words of the code under src/ apps/ tests/ bench/ fuzz/ web/ scripts/
// cmake/ (comments left out: a name only a comment mentions names nothing), and the options that
// `lodforge … --help` prints for the command and every subcommand. The synopses in fenced blocks
// (lines starting with `lodforge `) are checked as command lines, and architecture.md's module
// tables must match the files and the #include lines of each module.
//
// usage: node docs-check.mjs LODFORGE_BINARY [PAGE...]   (default: README.md docs/*.md)
// Prints `PAGE:LINE: what is wrong` per finding and a summary on stderr; exits 1 on any finding.
// OCCT_INCLUDE_DIR (default /usr/include/opencascade) is where OpenCASCADE names are looked up.
import { execFile } from 'node:child_process';
import { existsSync, readdirSync, readFileSync } from 'node:fs';
import { basename, dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';

const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
const [binary, ...pageArgs] = process.argv.slice(2);
if (!binary) {
  console.error('usage: node docs-check.mjs LODFORGE_BINARY [PAGE...]');
  process.exit(1);
}
const pages = pageArgs.length ? pageArgs.map((p) => ({ label: p, path: p }))
  : ['README.md', ...readdirSync(join(root, 'docs')).filter((f) => f.endsWith('.md')).sort()
      .map((f) => `docs/${f}`)].map((p) => ({ label: p, path: join(root, p) }));

// Genuine external names that our code does not spell out, each with why a page names it.
// (OpenCASCADE's `Package_Class` names are looked up in its headers instead, std/tbb/CLI/fmt
// names are not looked up at all.)
const EXTERNAL = new Map([
  ['PascalCase', 'style.md: the name of a naming style'],
  ['camelCase', 'style.md: the name of a naming style'],
  ['snake_case', 'style.md: the name of a naming style'],
  ['kName', 'style.md: the name of a naming style'],
  ['TCP_NODELAY', 'the socket option cpp-httplib sets for serve (set_tcp_nodelay)'],
  ['GLIBC_TUNABLES', "glibc's environment variable, measured against mallopt"],
  ['surface_style_transparent', 'the STEP entity a part\'s transparency comes from'],
  ['Kd', 'the .mtl keyword tinyobjloader reads a diffuse colour from'],
  ['UNSIGNED_BYTE', "glTF's componentType names (kUnsignedByte… in glb_writer.cpp)"],
  ['UNSIGNED_SHORT', "glTF's componentType names (kUnsignedByte… in glb_writer.cpp)"],
  ['UNSIGNED_INT', "glTF's componentType names (kUnsignedByte… in glb_writer.cpp)"],
  ['eglTerminate', 'the EGL call the renderer deliberately never makes'],
  ['meshopt_optimizeVertexCache', "meshoptimizer's optimiser the FIFO one is measured against"],
]);
const EXTERNAL_NAMESPACES = new Set(['std', 'tbb', 'CLI', 'fmt', 'nlohmann']);
const occtInclude = process.env.OCCT_INCLUDE_DIR || '/usr/include/opencascade';

// ---- The tree: files and folders, without what .gitignore names as build output.
const ignored = readFileSync(join(root, '.gitignore'), 'utf8').split('\n')
  .filter((l) => l.endsWith('/') && !l.includes('*'))
  .map((l) => ({ anchored: l.slice(0, -1).includes('/'), path: l.replace(/^\/|\/$/g, '') }));
const isIgnored = (rel) => ignored.some(({ anchored, path }) =>
  anchored ? rel === path || rel.startsWith(`${path}/`) : rel.split('/').includes(path));
const files = new Set();
const dirs = new Set();
(function walk(dir) {
  for (const entry of readdirSync(join(root, dir), { withFileTypes: true })) {
    const rel = dir ? `${dir}/${entry.name}` : entry.name;
    if (entry.name === '.git' || isIgnored(rel)) continue;
    if (entry.isDirectory()) {
      dirs.add(rel);
      walk(rel);
    } else {
      files.add(rel);
    }
  }
})('');
const stem = (f) => basename(f).replace(/\.[^.]*$/, '');
const basenames = new Set([...files].map((f) => basename(f)));
const stems = new Set([...files].map(stem));
const topLevel = new Set([...files, ...dirs].filter((p) => !p.includes('/')));
const modules = new Set([...dirs].filter((d) => /^src\/lodforge\/[^/]+$/.test(d))
  .map((d) => basename(d)));
const SOURCE_EXT = /\.(cpp|h|hpp|c|mjs|js|sh|py|cmake|lua|html|css|md)$/;
// A file's name has a source or data extension (`tileset.cpp`, `model.lfp`); `b.points` and
// `asset.generator` are members.
const FILE_NAME = new RegExp('^[\\w.<>*{},-]*\\.(cpp|h|hpp|c|mjs|js|sh|py|cmake|lua|html|css|md|' +
  'json|glb|gltf|ply|las|laz|lfp|lfc|png|step|stp|iges|igs|brep|brp|obj|stl|tsv|txt|seg|mesh|' +
  'tri|keys|so|pieces|xyz|csv|pts|mtl|bin|clang-format)$');

// ---- The words of the code, comments left out; string literals are kept (option names, JSON
// keys and attribute names live in them).
function stripComments(text, style) {
  let out = '';
  for (let i = 0; i < text.length; i++) {
    const c = text[i];
    if ((style === 'c' && c === '/' && text[i + 1] === '/') ||
        (style === 'hash' && c === '#' && (i === 0 || /\s/.test(text[i - 1])))) {
      while (i < text.length && text[i] !== '\n') i++;
      out += '\n';
    } else if (style === 'c' && c === '/' && text[i + 1] === '*') {
      const end = text.indexOf('*/', i + 2);
      i = end < 0 ? text.length : end + 1;
      out += ' ';
    } else if (c === '"' || c === "'" || (c === '`' && style === 'c')) {
      let j = i + 1;
      while (j < text.length && text[j] !== c && (c === '`' || text[j] !== '\n')) {
        j += text[j] === '\\' ? 2 : 1;
      }
      out += text.slice(i, j + 1);
      i = j;
    } else {
      out += c;
    }
  }
  return out;
}
const codeWords = new Set();
for (const f of files) {
  const name = basename(f);
  if (!/^(src|apps|tests|bench|fuzz|web|scripts|cmake|\.ci)\//.test(f) && f.includes('/')) continue;
  // This check and its wrapper are no code the docs describe (the wrapper plants wrong names).
  if (['tests/docs_check.sh', 'tests/js/docs-check.mjs'].includes(f)) continue;
  let style;
  if (/\.(cpp|h|hpp|c|mjs|js|css)$/.test(name)) style = 'c';
  else if (/\.(sh|py|cmake)$/.test(name) || ['CMakeLists.txt', 'Makefile'].includes(name) ||
           /^\.ci\/[^.]+$/.test(f)) style = 'hash';
  else if (/\.(lua|html)$/.test(name)) style = 'none';
  else continue;
  const code = stripComments(readFileSync(join(root, f), 'utf8'), style);
  for (const w of code.match(/[A-Za-z_][A-Za-z0-9_]*/g) ?? []) codeWords.add(w);
  // A magic spelled as characters, {'L', 'F', 'M', 'E', 'S', 'H', '3', '\0'}, is the word LFMESH3.
  const char = `'(?:\\\\.[0-9a-f]*|[^'\\\\])'`;
  const charArray = new RegExp(`\\{\\s*${char}(?:\\s*,\\s*${char})+\\s*\\}`, 'g');
  for (const [array] of code.matchAll(charArray)) {
    codeWords.add([...array.matchAll(/'([A-Za-z0-9])'/g)].map((m) => m[1]).join(''));
  }
  // CMake targets made in a loop: foreach(reader ply obj …) add_executable(fuzz_${reader} …).
  const loops = /foreach\((\w+)([^)]*)\)([\s\S]*?)endforeach/g;
  for (const [, name, items, body] of code.matchAll(loops)) {
    const use = new RegExp(`(\\w*)\\$\\{${name}\\}(\\w*)`, 'g');
    for (const [, before, after] of body.matchAll(use)) {
      for (const item of items.trim().split(/\s+/)) codeWords.add(before + item + after);
    }
  }
}

// ---- The options of `lodforge --help` and of every subcommand's --help, gathered once.
const runFile = promisify(execFile);
// '' | 'tiles' | 'generate cad' -> {options: name -> takes a value, subcommands}. CLI11 writes an
// option's value type one space after its names (`--threads N`), a flag's description further on.
const commands = new Map();
async function gatherHelp(path) {
  const { stdout } = await runFile(binary, [...path, '--help']);
  const options = new Map();
  const subcommands = new Set();
  let section = '';
  for (const line of stdout.split('\n')) {
    const heading = /^(\w[\w ]*):\s*$/.exec(line);
    if (heading) section = heading[1].toLowerCase();
    else if (section === 'options' && /^\s+-/.test(line)) {
      const [, names, value] = /^\s+(\S+)( \S)?/.exec(line);
      for (const name of names.split(',')) options.set(name, Boolean(value));
    } else if (section === 'subcommands' && /^\s+\S/.test(line)) {
      subcommands.add(line.trim().split(/\s+/)[0]);
    }
  }
  if (!options.has('--help')) throw new Error(`no options in \`${path.join(' ')} --help\``);
  commands.set(path.join(' '), { options, subcommands });
  await Promise.all([...subcommands].map((s) => gatherHelp([...path, s])));
}
await gatherHelp([]);
const allOptions = new Map([...commands.values()].flatMap((c) => [...c.options]));
const subcommandNames = new Set([...commands.keys()].flatMap((k) => k.split(' ')).filter(Boolean));

// ---- Checks: each returns its findings; `counts` says what was examined.
const counts = { path: 0, name: 0, option: 0, command: 0, skipped: 0 };
const skip = () => {
  counts.skipped++;
  return [];
};

// `<x>`, `*`, `…` and NNNN stand for any part of one path component.
function resolvesPath(p) {
  const brace = /\{([^{}]*)\}/.exec(p);
  if (brace) {
    return brace[1].split(',').every((alt) =>
      resolvesPath(p.slice(0, brace.index) + alt + p.slice(brace.index + brace[0].length)));
  }
  const q = p.replace(/\/$/, '');
  const candidates = ['', 'src/lodforge/', 'apps/lodforge/', 'tests/'].map((base) => base + q);
  if (!/[<*…]|\.\.\.|NNN/.test(q)) {
    return candidates.some((c) => dirs.has(c) ||
      (!p.endsWith('/') && (files.has(c) || files.has(`${c}.h`) || files.has(`${c}.cpp`))));
  }
  const pool = p.endsWith('/') ? [...dirs]
    : [...dirs, ...files, ...[...files].map((f) => f.replace(/\.(h|cpp)$/, ''))];
  return candidates.some((c) => {
    const re = new RegExp(`^${c.replace(/[.+?^${}()|[\]\\]/g, '\\$&').replace(/<[^>]*>/g, '[^/]+')
      .replace(/\*/g, '[^/]*').replace(/…|\\\.\\\.\\\./g, '[^/]*').replace(/N{3,}/g, '\\d+')}$`);
    return pool.some((f) => re.test(f));
  });
}

// A path is ours when it starts at a top-level entry of the checkout (not a build output), or at a
// module folder (`simplify/progressive.cpp`, `io/format_advice`) with no extension or a source
// one, or is a source file's bare name. `OUT.work/state.json`, `tiles/*.glb`, `model.lfp`, `.lfp`
// and `/usr/bin/time` are what a run or a user makes, or outside the checkout.
function checkPath(token) {
  const p = token.replace(/[.,;:]$/, '');
  const outside = /^[a-z]+:\/\//.test(p) || /^(\/|\.\.\/|~)/.test(p);
  if (outside || (/^\.[\w-]+$/.test(p) && !topLevel.has(p))) return skip(); // or `.lfp`
  const first = p.split('/')[0];
  const ext = /\.[A-Za-z0-9]+$/.exec(p.replace(/\/$/, ''))?.[0] ?? '';
  const ours = p.includes('/')
    ? (topLevel.has(first) && !isIgnored(p.replace(/\/$/, ''))) ||
      (modules.has(first) && (!ext || SOURCE_EXT.test(ext)))
    : topLevel.has(p) || (SOURCE_EXT.test(ext) && !/[<*]/.test(p));
  if (!ours) return skip();
  counts.path++;
  const found = p.includes('/') ? resolvesPath(p) : basenames.has(p);
  return found ? [] : [`\`${token}\` names no file in the tree`];
}

// OpenCASCADE's `Package_Class` and `Package_Class::Member`, in its headers.
function occtNameExists(parts) {
  if (parts.length > 2 || !/^[A-Z][A-Za-z0-9]*[a-z][A-Za-z0-9]*_[A-Za-z0-9]+$/.test(parts[0])) {
    return false;
  }
  const header = join(occtInclude, `${parts[0]}.hxx`);
  if (!existsSync(header)) return false;
  return parts.length === 1 || new RegExp(`\\b${parts[1]}\\b`).test(readFileSync(header, 'utf8'));
}

// One part of a name: a word of the code, a file's name without extension (`ply_reader`), a
// subcommand or an EXTERNAL name. `<Placeholder>`, `*` and `…` stand for any part of a word.
function nameExists(name) {
  if (/[<*…]/.test(name)) {
    const re = new RegExp(`^${name.replace(/<[^>]*>|\*|…/g, '\\w*')}$`);
    return [...codeWords, ...stems].some((w) => re.test(w));
  }
  return codeWords.has(name) || stems.has(name) || subcommandNames.has(name) || EXTERNAL.has(name);
}

// Does one word look like a name of the code rather than an English word, a value or a
// placeholder? camelCase, PascalCase, snake_case, kConstant, or capitals with a digit or an
// underscore (`LFMESH3`, `COLOR_0`, `O_EXCL`); plain lowercase words and plain capitals are not.
function looksLikeName(word) {
  if (!/^[A-Za-z_]/.test(word) || !/[A-Za-z]/.test(word)) return false;
  if (/[a-z]/.test(word) && /[A-Z]/.test(word)) return true;
  return word.includes('_') || (/[A-Z]{2}/.test(word) && /\d/.test(word));
}

// `Type::member`, `object.field`, `a->b`, `name()`, `name(args)` (the callee), `Type<Arg>`, a
// gtest name `Suite.Test` or `Suite.*`: every part must exist.
function checkName(token) {
  const call = callee(token);
  const expr = (call ?? token).replace(/\[[^\]]*\]/g, ''); // `objects[o].vertexOffset`
  const split = (e) => e.split(/::|->|\./);
  const parts = split(expr);
  if (!parts.every((p) => /^[A-Za-z_<…*][\w<>…*]*$/.test(p))) return skip();
  if (EXTERNAL_NAMESPACES.has(parts[0])) return skip();
  if (parts.length === 1 && !call && !/[<…]/.test(parts[0]) && !looksLikeName(parts[0])) {
    return skip();
  }
  counts.name++;
  if (EXTERNAL.has(token) || occtNameExists(parts)) return [];
  // `add<Name>` is a placeholder, `Result<Model>` a template: either reading will do.
  const template = /^([^<>]+)<([^<>]*)>$/.exec(expr);
  const asTemplate = template && [...split(template[1]), template[2]]
    .filter((p) => !/^[A-Z]?$/.test(p)).every(nameExists);
  if (asTemplate || parts.filter((p) => p !== '*').every(nameExists)) return [];
  return [`\`${token}\` names nothing in the code`];
}

// A `lodforge …` command line: each subcommand one there is, each option one of its subcommand's
// (or of an enclosing command's: the root falls through), each path of ours a file. `anyScope`:
// a bare option in prose, which is fine if any subcommand has it. Returns findings and the scope.
function checkCommand(words, { scope = [], anyScope = false } = {}) {
  counts.command++;
  const errors = [];
  let afterOption = false;
  for (const raw of words) {
    const alternatives = raw.replace(/^[[(]+|[\])]+$/g, '').split('|').filter(Boolean);
    const isValue = afterOption;
    afterOption = false;
    for (const word of alternatives.map((w) => w.replace(/^[[(]+|[\])]+$/g, ''))) {
      if (/^--?[A-Za-z]/.test(word)) {
        const option = word.split('=')[0];
        counts.option++;
        const known = anyScope ? allOptions
          : [[], ...scope.map((_, i) => scope.slice(0, i + 1))].reverse()
            .map((s) => commands.get(s.join(' ')).options).find((o) => o.has(option));
        if (!known?.has(option)) {
          errors.push(anyScope ? `\`${option}\` is no option of lodforge`
            : `\`${option}\` is no option of \`${['lodforge', ...scope].join(' ')}\``);
        }
        afterOption = (known?.get(option) ?? true) && !word.includes('=');
      } else if (isValue || anyScope) {
        continue;
      } else if (commands.get(scope.join(' ')).subcommands.size) {
        const next = [...scope, word].join(' ');
        if (commands.has(next)) scope = [...scope, word];
        else if (/^[a-z]+$/.test(word)) errors.push(`\`lodforge ${next}\`: no such subcommand`);
      } else if (word.includes('/')) {
        errors.push(...checkPath(word));
      }
    }
  }
  return { errors, scope };
}

// One code span: what it is, and its findings.
function checkSpan(code) {
  const text = code.trim();
  const words = text.split(/\s+/);
  if (!text || /^[\d.,%×x+\-−~]*\d[\d.,%×x+\-−~]*[A-Za-z]{0,4}$/.test(text) ||
      /^[0-9a-f]{7,40}$/.test(text)) {
    return skip(); // a number, a size, a commit
  }
  const commandsChained = text.split(/\s+(?:&&|\|\||;|\|)\s+/);
  if (commandsChained.length > 1) return commandsChained.flatMap(checkSpan); // `a && b`, `a | b`
  const at = words.indexOf('lodforge');
  if (at >= 0 && at < words.length - 1) return checkCommand(words.slice(at + 1)).errors;
  if (commands.has(words[0]) && words.length > 1 &&
      (commands.has(`${words[0]} ${words[1]}`) || words.some((w) => w.startsWith('-')))) {
    return checkCommand(words).errors; // `tiles --surface`, `generate cad`
  }
  if (/^--?[A-Za-z]/.test(text)) {
    if (/^-[A-Za-z][A-Za-z0-9=]/.test(text)) return skip(); // a compiler's flag: -O3, -UNDEBUG
    return checkCommand(words, { anyScope: true }).errors;
  }
  const include = /^#include "(lodforge\/.+)"$/.exec(text);
  if (include) return checkPath(`src/${include[1]}`);
  if (callee(text)) return checkName(text);
  const assignment = /^(\S+) = \S+$/.exec(text) ?? /^\$\{?([A-Za-z_]\w*)\}?$/.exec(text);
  if (assignment) return checkName(assignment[1]); // `Options::field = 0.2`, `$LODFORGE_CAD_MODULE`
  if (words.length > 1 || /^[A-Z_][A-Z0-9_]*=/.test(text)) return checkPhrase(text, words);
  if (text.includes('/') || FILE_NAME.test(text)) return checkPath(text);
  return checkName(text);
}

// `name(args)` or `Name{args}` whose first bracket closes at the end: the name called.
function callee(text) {
  const m = /^([\w:.<>…*-]+?)([({])/.exec(text);
  if (!m) return null;
  const close = m[2] === '(' ? ')' : '}';
  for (let i = m[1].length, depth = 0; i < text.length; i++) {
    if (text[i] === m[2]) depth++;
    else if (text[i] === close && --depth === 0) return i === text.length - 1 ? m[1] : null;
  }
  return null;
}

// A span with spaces that is not a `lodforge` command line: `make test` (a target of the
// Makefile), `BENCH_ONLY=cad scripts/bench.sh` (the variables and the script), `u64 nameOffset`
// (a field of a layout). Anything else is prose or code.
function checkPhrase(text, words) {
  if (words[0] === 'make' && words.length === 2) {
    counts.name++;
    const makefile = readFileSync(join(root, 'Makefile'), 'utf8');
    const found = new RegExp(`^${words[1]}:`, 'm').test(makefile);
    return found ? [] : [`\`${text}\`: no such make target`];
  }
  let i = 0;
  const errors = [];
  for (; i < words.length && /^[A-Z_][A-Z0-9_]*=/.test(words[i]); i++) {
    errors.push(...checkName(words[i].split('=')[0]));
  }
  if (i > 0 || topLevel.has(words[0].split('/')[0])) {
    const script = i < words.length && words[i].includes('/') ? checkPath(words[i]) : [];
    return [...errors, ...script];
  }
  const field = /^(?:u8|u16|u32|u64|i32|i64|f32|f64)(?:\[\d+\])? ([A-Za-z]\w*)$/.exec(text);
  if (field && looksLikeName(field[1])) {
    return checkName(field[1]).map((e) => e.replace(`\`${field[1]}\``, `\`${text}\``));
  }
  return skip();
}

// ---- Markdown: code spans (CommonMark: a run of n backticks to the next run of exactly n, inside
// one paragraph, which may span lines; reported at the line of the opening run) and the lines of
// fenced blocks. Table rows and headings are blocks of one line.
function scanPage(text) {
  const spans = [];
  const fenced = [];
  let fence = null;
  let paragraph = [];
  const flush = () => {
    spansIn(paragraph, spans);
    paragraph = [];
  };
  text.split('\n').forEach((line, i) => {
    const marker = /^\s*(`{3,}|~{3,})\s*(\S*)\s*$/.exec(line);
    if (fence) {
      const closes = marker && marker[1][0] === fence[0] && marker[1].length >= fence.length;
      if (closes && !marker[2]) fence = null;
      else fenced.push({ text: line, line: i + 1 });
    } else if (marker) {
      flush();
      fence = marker[1];
    } else if (!line.trim() || /^\s*(\||#)/.test(line)) {
      flush();
      spansIn([{ text: line, line: i + 1 }], spans);
    } else {
      paragraph.push({ text: line, line: i + 1 });
    }
  });
  flush();
  return { spans, fenced };
}

function spansIn(lines, spans) {
  const s = lines.map((l) => l.text).join('\n');
  const lineAt = (offset) => lines[s.slice(0, offset).split('\n').length - 1].line;
  const runEnd = (i) => {
    while (s[i] === '`') i++;
    return i;
  };
  for (let i = 0; i < s.length;) {
    if (s[i] === '\\') {
      i += 2;
    } else if (s[i] !== '`') {
      i++;
    } else {
      const open = runEnd(i);
      let close = -1;
      for (let k = open; k < s.length && close < 0;) {
        if (s[k] !== '`') k++;
        else if (runEnd(k) - k === open - i) close = k;
        else k = runEnd(k);
      }
      if (close < 0) {
        i = open;
        continue;
      }
      let code = s.slice(open, close).replace(/\n/g, ' ');
      if (code.startsWith(' ') && code.endsWith(' ') && code.trim()) code = code.slice(1, -1);
      spans.push({ code, line: lineAt(i) });
      i = close + (open - i);
    }
  }
}

// A fenced block's `lodforge …` lines, and the lines right below one that start with `[` or `-`
// (its continuation, checked in its subcommand). `#` starts a comment.
function checkFenced(fenced) {
  const findings = [];
  let scope = null;
  let previousLine = -1;
  for (const { text, line } of fenced) {
    const body = text.replace(/(^|\s)#.*$/, '').trim();
    let result;
    if (/^lodforge(\s|$)/.test(body)) {
      result = checkCommand(body.split(/\s+/).slice(1));
    } else if (scope && previousLine === line - 1 && /^[[-]/.test(body)) {
      result = checkCommand(body.split(/\s+/), { scope });
    } else {
      scope = null;
      continue;
    }
    scope = result.scope;
    previousLine = line;
    findings.push(...result.errors.map((e) => ({ line, error: e })));
  }
  return findings;
}

// architecture.md's module table lists exactly each module's files (the stems of its .h and
// .cpp, family folders included), so a new or moved file is not left off the map; its includes
// table says which modules each one includes, as the #include lines of src/lodforge/ do.
const includeLine = /#include "lodforge\/(\w+)\//g;
const sourcesOf = (folder) =>
  [...files].filter((f) => f.startsWith(`${folder}/`) && /\.(h|cpp)$/.test(f));
function checkModuleTable(text) {
  const findings = [];
  const lines = text.split('\n');
  const header = lines.findIndex((l) => /^\|\s*module\s*\|\s*files\s*\|/.test(l));
  for (let i = header + 2; header >= 0 && lines[i]?.startsWith('|'); i++) {
    const [, module, cell] = lines[i].split('|').map((c) => c.trim());
    const folder = module === 'apps' ? 'apps/lodforge' : `src/lodforge/${module}`;
    const have = new Set(sourcesOf(folder).map(stem));
    const listed = new Set((cell.match(/`[^`]+`/g) ?? []).map((c) => c.slice(1, -1))
      .filter((c) => !c.endsWith('/')).map(stem)); // `io/mesh/` heads a family
    const say = (error) => findings.push({ line: i + 1, error });
    for (const s of listed) if (!have.has(s)) say(`\`${s}\` is no file of ${folder}/`);
    for (const s of have) if (!listed.has(s)) say(`${folder}/ has \`${s}\`, not listed`);
  }
  const includes = lines.findIndex((l) => /^\|\s*module\s*\|\s*includes\s*\|/.test(l));
  for (let i = includes + 2; includes >= 0 && lines[i]?.startsWith('|'); i++) {
    const [, names, cell] = lines[i].split('|').map((c) => c.trim());
    const row = names.split(/,\s*/).filter((m) => modules.has(m));
    const said = new Set(cell.replace(/\([^)]*\)|:.*$/g, '').split(/,|\band\b/)
      .map((w) => w.trim()).filter((m) => modules.has(m)));
    const included = new Set(row.flatMap((m) => sourcesOf(`src/lodforge/${m}`)
      .flatMap((f) => [...readFileSync(join(root, f), 'utf8').matchAll(includeLine)]
        .map((match) => match[1])).filter((x) => x !== m)));
    const say = (error) => findings.push({ line: i + 1, error });
    for (const m of included) if (!said.has(m)) say(`${names} includes ${m}, not said`);
    for (const m of said) if (!included.has(m)) say(`${names} includes no ${m}`);
  }
  return findings;
}

// ---- Run.
let findingCount = 0;
let spanCount = 0;
let fencedCount = 0;
for (const { label, path } of pages) {
  const text = readFileSync(path, 'utf8');
  const { spans, fenced } = scanPage(text);
  spanCount += spans.length;
  const findings = spans.flatMap(({ code, line }) =>
    checkSpan(code).map((error) => ({ line, error })));
  const commandLines = counts.command;
  findings.push(...checkFenced(fenced));
  fencedCount += counts.command - commandLines;
  if (basename(path) === 'architecture.md') findings.push(...checkModuleTable(text));
  findings.sort((a, b) => a.line - b.line);
  for (const { line, error } of findings) console.log(`${label}:${line}: ${error}`);
  findingCount += findings.length;
}
console.error(`docs check: ${spanCount} code spans in ${pages.length} pages, and ${fencedCount} ` +
  `command lines of fenced blocks: ${counts.path} paths, ${counts.name} names of the code, ` +
  `${counts.option} options (in ${counts.command} command lines and option spans); ` +
  `${counts.skipped} spans not names (prose, values, code, run-time paths); ` +
  `${findingCount} findings`);
process.exitCode = findingCount ? 1 : 0;
